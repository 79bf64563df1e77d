#!/usr/bin/env bash
# Session 19, call 6 (kind nvidia-h200-x2): fa8c6cf: the several-devices
# engine tests on rt-pipeline with the validation layer on two H200s (call
# 5's 150 s limit stopped them), then the torus quarter and the one call
# alternated 5 rounds.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res
trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dk $B/layers/libVkLayer_khronos_validation.so.xz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait) &
gen=$!
t0=$(date +%s)
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 330 $B/rthdist_engine_tests \
  --gtest_filter='SeveralDevices*' > /tmp/res/engine_tests.txt 2>&1
echo "engine tests exit $? in $(( $(date +%s) - t0 )) s"
grep -E "^\[  (PASSED|FAILED)|tests ran|FAILED  \]|^\[       OK" /tmp/res/engine_tests.txt | head -20
wait $gen; sync; cat $S/*.ply > /dev/null
one() {  # label args...
  local label=$1; shift
  $B/rthdist --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/res/$label.err
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)))" /tmp/res/$label.json 2>&1 | head -c 200)"
}
for r in 1 2 3 4 5; do
  one call_$r
  one q_$r --memory-budget 22400
done
