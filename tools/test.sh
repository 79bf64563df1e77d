#!/usr/bin/env bash
# Quickstart command 2 (README): installs the dependencies, builds the release
# preset (build/) and runs the whole test suite. Fails on any test failure and
# when any GPU test was skipped (tools/check_skips.sh). Then builds the Python
# package once (scikit-build-core, offline, into build-python/), installs it
# into a venv that also sees Debian's numpy/scipy (the system Python is
# externally managed, PEP 668) and runs its pytest suite (tests/python: every
# backend, none skipped). .ci/run calls this verbatim.
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/install-deps.sh
cmake --preset release
cmake --build --preset release -j "$(nproc)"
log=build/ctest.log
ctest --preset release -j "$(nproc)" 2>&1 | tee "$log"
bash tools/check_skips.sh build "$log"

py=build-python/venv/bin/python
/usr/bin/python3 -m venv --system-site-packages build-python/venv
CMAKE_BUILD_PARALLEL_LEVEL="$(nproc)" "$py" -m pip install -q --no-build-isolation --no-index --no-deps .
RTHDIST_CLI=build/rthdist "$py" -m pytest -q -p no:cacheprovider -rs tests/python
