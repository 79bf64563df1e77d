#!/usr/bin/env bash
# Session 20, call 1 (kind nvidia-h200-x2, 32 cores; one device unless "two"):
# the scatter's 16-byte slots (rthdist) against 40e74b8 (rthdist-before):
# the one call and the torus quarter (--memory-budget 22400) alternated, 3
# rounds; the two devices' quarter once each; one quarter's whole submit
# trace kept; then the scale suite under the quarter's budget (PROCS=2,
# --verify) on the three largest cases with the new build.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)))" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt
  [ "$label" = q_after_3 ] || rm $RES/$label.trace
}
for r in 1 2 3; do
  one call_before_$r rthdist-before
  one call_after_$r rthdist
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
one q_two_before_1 rthdist-before --memory-budget 22400 --devices 0,1
one q_two_after_1 rthdist --memory-budget 22400 --devices 0,1
xz -9 $RES/q_after_3.trace
rm -f $S/*.ply
PROCS=2 EXTRA="--memory-budget 22400" timeout 330 bash tools/bench/gpu_scale_suite.sh $B $RES/suite torus-300x400 cube-300x300 shell-400x400 > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-200 $RES/suite/lines.txt
