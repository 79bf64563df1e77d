#!/usr/bin/env bash
# Quickstart command 2 (README): installs the dependencies, builds the release
# preset (build/) and runs the whole test suite. Fails on any test failure and
# when any GPU test was skipped (tools/check_skips.sh). .ci/run calls this
# verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/install-deps.sh
cmake --preset release
cmake --build --preset release -j "$(nproc)"
log=build/ctest.log
ctest --preset release -j "$(nproc)" 2>&1 | tee "$log"
bash tools/check_skips.sh build "$log"
