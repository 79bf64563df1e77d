#!/usr/bin/env bash
# Session 20, call 2 (kind nvidia-h200-x2, 32 cores): pieces in a multiple
# of the lanes (rthdist) against 3e2c472 (rthdist-before) on two devices:
# the torus quarter (--memory-budget 22400 --devices 0,1) alternated, 3
# rounds, one device's quarter beside it; then 1B x 1B on two devices, one
# process of each build.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label binary files... -- args...
  local label=$1 bin=$2 a=$3 b=$4; shift 4
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $a $b > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; c=d['counters']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'chunks', c['a_to_b']['query_chunks'], c['b_to_a']['query_chunks'])" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
for r in 1 2 3; do
  one q_two_before_$r rthdist-before $S/a.ply $S/b.ply --memory-budget 22400 --devices 0,1
  one q_two_after_$r rthdist $S/a.ply $S/b.ply --memory-budget 22400 --devices 0,1
  one q_one_after_$r rthdist $S/a.ply $S/b.ply --memory-budget 22400
done
rm -f $S/a.ply $S/b.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/c.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/d.ply & wait); sync; cat $S/c.ply $S/d.ply > /dev/null
one 1B_two_before_1 rthdist-before $S/c.ply $S/d.ply --devices 0,1
one 1B_two_after_1 rthdist $S/c.ply $S/d.ply --devices 0,1
one 1B_one_after_1 rthdist $S/c.ply $S/d.ply
rm -f $S/*.ply
