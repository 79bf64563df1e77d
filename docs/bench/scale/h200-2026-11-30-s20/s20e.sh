#!/usr/bin/env bash
# Session 20, call 5 (kind nvidia-h200: one H200, 16 cores): the session's
# code (6cf598d) on the 16-core host, where session 19 measured the quarter
# at 2.3-2.4x the one call: the one call and the torus quarter
# (--memory-budget 22400) alternated, 3 rounds; then 1B x 1B once.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label a b args...
  local label=$1 a=$2 b=$3; shift 3
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" $a $b > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'gpu upload', round(g['upload']), 'pieces', round(t.get('pieces',0)), 'wall', round(t['wall']))" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
for r in 1 2 3; do
  one call_$r $S/a.ply $S/b.ply
  one q_$r $S/a.ply $S/b.ply --memory-budget 22400
done
rm -f $S/a.ply $S/b.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/c.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/d.ply & wait); sync; cat $S/c.ply $S/d.ply > /dev/null
one 1B_1 $S/c.ply $S/d.ply
one 1B_2 $S/c.ply $S/d.ply
rm -f $S/*.ply
