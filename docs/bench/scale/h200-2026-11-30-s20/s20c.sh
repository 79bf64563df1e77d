#!/usr/bin/env bash
# Session 20, call 3 (kind nvidia-h200-x2, 32 cores; one device): the
# chunked upload as packed floats (rthdist, 4c38b9c) against 99b94f9
# (rthdist-before): GPU tests with the validation layer on rt-pipeline
# (LargeSizes.*, the engine's OutOfCore.*), then the one call and the torus
# quarter (--memory-budget 22400) alternated, 3 rounds.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
t0=$(date +%s)
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 100 $B/rthdist_gpu_tests --gtest_filter='LargeSizes.*' > $RES/gpu_tests.txt 2>&1
echo "gpu tests exit $? in $(( $(date +%s) - t0 )) s"; grep -E "^\[  (PASSED|FAILED)|FAILED  \]" $RES/gpu_tests.txt | head
t0=$(date +%s)
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 120 $B/rthdist_engine_tests --gtest_filter='OutOfCore.*' > $RES/engine_tests.txt 2>&1
echo "engine tests exit $? in $(( $(date +%s) - t0 )) s"; grep -E "^\[  (PASSED|FAILED)|FAILED  \]" $RES/engine_tests.txt | head
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'upload', round(t['upload']), 'gpu upload', round(g['upload']), 'pieces', round(t.get('pieces',0)))" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
for r in 1 2 3; do
  one call_before_$r rthdist-before
  one call_after_$r rthdist
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
rm -f $S/*.ply
