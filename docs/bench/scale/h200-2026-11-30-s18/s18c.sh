#!/usr/bin/env bash
# Session 18, call 3: ebccadc (the side-by-side leaf split): the same as
# call 1: the GPU tests with the validation layer
# (LargeSizes, the oracle and density suites), then the scale suite
# (PROCS=2, --verify).
set -uo pipefail
B=.devs; mkdir -p $OUT /tmp/res
trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dk $B/layers/libVkLayer_khronos_validation.so.xz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
t0=$(date +%s)
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 240 $B/rthdist_gpu_tests \
  --gtest_filter='LargeSizes.*:*Oracle*:*Density*:*Narrow*' > /tmp/res/gpu_tests.txt 2>&1
echo "gpu tests exit $? in $(( $(date +%s) - t0 )) s"
grep -E "^\[  (PASSED|FAILED)|tests ran|FAILED  \]" /tmp/res/gpu_tests.txt | head -20
PROCS=2 bash tools/bench/gpu_scale_suite.sh $B /tmp/res/suite > /tmp/res/suite.txt 2>&1
echo "suite exit $?"; cat /tmp/res/suite/lines.txt
