#!/usr/bin/env bash
# Session 19, call 5 (kind nvidia-h200-x2): the session's last code: the
# engine's out-of-core and several-devices tests on rt-pipeline with the
# validation layer, then the scale suite under the quarter's budget
# (EXTRA="--memory-budget 22400": pieces in space, PROCS=2, --verify) on
# the three largest cases.
set -uo pipefail
B=.devs; mkdir -p $OUT /tmp/res
trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dk $B/layers/libVkLayer_khronos_validation.so.xz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
t0=$(date +%s)
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 150 $B/rthdist_engine_tests \
  --gtest_filter='OutOfCore.*:SeveralDevices*' > /tmp/res/engine_tests.txt 2>&1
echo "engine tests exit $? in $(( $(date +%s) - t0 )) s"
grep -E "^\[  (PASSED|FAILED)|tests ran|FAILED  \]" /tmp/res/engine_tests.txt | head -20
PROCS=2 EXTRA="--memory-budget 22400" timeout 420 bash tools/bench/gpu_scale_suite.sh $B /tmp/res/suite torus-300x400 cube-300x300 shell-400x400 > /tmp/res/suite.txt 2>&1
echo "suite exit $?"; cat /tmp/res/suite/lines.txt
