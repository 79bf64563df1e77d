#!/usr/bin/env bash
# Session 20, call 9 (kind nvidia-h200, 16 cores): the keys and scatter
# passes spread only for a set in space order (rthdist: PointIndex::spaceOrder)
# against the build with them in input order (rthdist-before): the one call
# and the torus quarter alternated, 2 rounds, with the index builds'
# phases; then the scale suite's torus, one call and under the quarter's
# budget (PROCS=1, --verify).
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'gpu index', round(g['index']), 'pieces', round(t.get('pieces',0)))" $RES/$label.json 2>&1 | head -c 200)"
  grep "between marks" $RES/$label.trace | awk '{print "device", $14, "keys", $21, "scatter", $23}' | head -4 | tr '\n' ' '; echo
  xz -9 $RES/$label.trace
}
for r in 1 2; do
  one call_before_$r rthdist-before
  one call_after_$r rthdist
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
rm -f $S/*.ply
PROCS=1 timeout 70 bash tools/bench/gpu_scale_suite.sh $B $RES/suite torus-300x400 > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-150 $RES/suite/lines.txt
PROCS=1 EXTRA="--memory-budget 22400" timeout 70 bash tools/bench/gpu_scale_suite.sh $B $RES/quarter torus-300x400 > $RES/quarter.txt 2>&1
echo "quarter exit $?"; cut -c1-150 $RES/quarter/lines.txt
