#!/usr/bin/env bash
# Usage: tools/check_skips.sh BUILD_DIR [CTEST_CONSOLE_LOG]
# Run after ctest. Fails when a GPU test was skipped: GPU tests GTEST_SKIP
# when no Vulkan device qualifies, and in CI lavapipe must qualify, so a skip
# there is a broken setup, not a pass.
# Skips are found two ways, so that both kinds of registration are covered:
#   - ctest's own "***Skipped" (gtest_discover_tests sets SKIP_REGULAR_EXPRESSION),
#   - "[  SKIPPED ]" in any test's output in Testing/Temporary/LastTest.log
#     (a whole gtest executable added with add_test reports "Passed" to ctest).
# A skipped test is a GPU test when it carries the ctest label "gpu" or "cli",
# or its name or skip message mentions GPU/Vulkan/ray/device. Other skips are
# listed as warnings.
set -euo pipefail
build_dir=$1
console_log=${2:-}
last_log=$(ls -t "$build_dir"/Testing/Temporary/LastTest.log "$build_dir"/Testing/Temporary/LastTest_*.log 2>/dev/null | head -n 1 || true)
if [ -z "$last_log" ]; then
  echo "check_skips: no $build_dir/Testing/Temporary/LastTest.log: run ctest first" >&2
  exit 1
fi

# "<ctest name>\t<evidence>" per skip.
skips=$(
  {
    # LastTest.log: "12/491 Test: name" opens a test's record; gtest prints
    # "[  SKIPPED ] Suite.Name" (and a message line before it) for each skip.
    awk '
      /^[0-9]+\/[0-9]+ Test: / { sub(/^[0-9]+\/[0-9]+ Test: /, ""); name = $0; msg = ""; grab = 0; next }
      grab { msg = $0; grab = 0; next }
      /: Skipped$/ { grab = 1; next }
      /^\[  SKIPPED \] .* \([0-9]+ ms\)$/ {
        t = $0; sub(/^\[  SKIPPED \] /, "", t); sub(/ \([0-9]+ ms\)$/, "", t)
        print name "\t" t ": " msg; msg = ""
      }
    ' "$last_log"
    if [ -n "$console_log" ] && [ -f "$console_log" ]; then
      sed -n 's/^.*Test *#[0-9]*: \([^ ]*\) .*\*\*\*Skipped.*$/\1\tctest: Skipped/p' "$console_log"
    fi
  } | sort -u
)
if [ -z "$skips" ]; then
  echo "check_skips: no skipped tests"
  exit 0
fi

gpu_names=$(ctest --test-dir "$build_dir" -N -L 'gpu|cli' | sed -n 's/^ *Test *#[0-9]*: \([^ ]*\).*$/\1/p' | sort -u)
bad=0
while IFS=$'\t' read -r name evidence; do
  first=${name%% *}
  if grep -qxF -- "$first" <<<"$gpu_names" ||
    grep -qiE 'gpu|vulkan|ray|rt-?pipeline|lavapipe|device' <<<"$name $evidence"; then
    echo "check_skips: GPU test SKIPPED: $name: $evidence" >&2
    bad=1
  else
    echo "check_skips: warning: skipped (not a GPU test): $name: $evidence" >&2
  fi
done <<<"$skips"
if [ $bad = 1 ]; then
  echo "check_skips: GPU tests were skipped: no usable Vulkan ray-tracing device." >&2
  echo "check_skips: CI must have lavapipe (mesa-vulkan-drivers >= 24.1 from bookworm-backports," >&2
  echo "check_skips: tools/install-deps.sh); './build/rthdist --list-devices' says why each device was rejected." >&2
  exit 1
fi
