#!/usr/bin/env bash
# Session 20, call 6 (kind nvidia-h200: one H200, 16 cores): the keys pass
# keeping each point's cell for the scatter (rthdist, 5a81abe) against
# 6cf598d (rthdist-before): the torus quarter (--memory-budget 22400)
# alternated, 3 rounds, the one call beside it; then the torus under the
# quarter's budget through the scale suite (PROCS=2, --verify).
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)))" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
one call_1 rthdist
for r in 1 2 3; do
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
one call_2 rthdist
rm -f $S/a.ply $S/b.ply
PROCS=2 EXTRA="--memory-budget 22400" timeout 150 bash tools/bench/gpu_scale_suite.sh $B $RES/quarter torus-300x400 > $RES/quarter.txt 2>&1
echo "quarter exit $?"; cut -c1-200 $RES/quarter/lines.txt
