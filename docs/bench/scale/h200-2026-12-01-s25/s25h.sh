#!/usr/bin/env bash
# Session 25, call 8 (kind nvidia-h200-x2: two H200s, 32 cores): issue 33's
# out-of-core and two-device figures on the session's last build: the torus
# 300M x 400M one call, under a quarter of its memory (--memory-budget
# 22400) on one device and on two (--devices 0,1), 3 rounds alternated;
# then 1B x 1B on one device and on two, one process each.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label a b args...
  local label=$1 a=$2 b=$3; shift 3
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" $a $b > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'wall', round(t['wall']))" $RES/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
for r in 1 2 3; do
  one call_$r $S/a.ply $S/b.ply
  one quarter_one_$r $S/a.ply $S/b.ply --memory-budget 22400
  one quarter_two_$r $S/a.ply $S/b.ply --memory-budget 22400 --devices 0,1
done
rm -f $S/a.ply $S/b.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/c.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/d.ply & wait); sync; cat $S/c.ply $S/d.ply > /dev/null
one 1B_one $S/c.ply $S/d.ply
one 1B_two $S/c.ply $S/d.ply --devices 0,1
rm -f $S/*.ply
