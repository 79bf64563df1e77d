#!/usr/bin/env bash
# Usage: tools/check_skips.sh BUILD_DIR CTEST_LOG
# Fails when a GPU test was skipped. GPU tests skip (GTEST_SKIP) when no
# Vulkan device qualifies; in CI lavapipe must qualify, so a skip there is a
# broken setup, not a pass. GPU tests = ctest label "gpu" or "cli", or a name
# that says GPU/Vulkan/ray. Other skips are listed as warnings.
set -euo pipefail
build_dir=$1
log=$2

# "  12/140 Test  #12: Suite.Name ........***Skipped   0.01 sec"
mapfile -t skipped < <(sed -n 's/^.*Test *#[0-9]*: \([^ ]*\) .*\*\*\*Skipped.*$/\1/p' "$log" | sort -u)
if [ "${#skipped[@]}" = 0 ]; then
  echo "check_skips: no skipped tests"
  exit 0
fi
mapfile -t gpu_tests < <(ctest --test-dir "$build_dir" -N -L 'gpu|cli' |
  sed -n 's/^ *Test *#[0-9]*: \([^ ]*\).*$/\1/p' | sort -u)

bad=0
for t in "${skipped[@]}"; do
  is_gpu=0
  for g in "${gpu_tests[@]}"; do [ "$g" = "$t" ] && { is_gpu=1; break; }; done
  if [ $is_gpu = 0 ] && echo "$t" | grep -qiE 'gpu|vulkan|ray|rtpipeline|lavapipe|device'; then is_gpu=1; fi
  if [ $is_gpu = 1 ]; then
    echo "check_skips: GPU test SKIPPED: $t" >&2
    bad=1
  else
    echo "check_skips: warning: skipped (not a GPU test): $t" >&2
  fi
done
if [ $bad = 1 ]; then
  echo "check_skips: GPU tests were skipped: no usable Vulkan ray-tracing device." >&2
  echo "check_skips: CI must have lavapipe (mesa-vulkan-drivers >= 24.1, tools/install-deps.sh);" >&2
  echo "check_skips: see 'build/rthdist --list-devices' for why each device was rejected." >&2
  exit 1
fi
