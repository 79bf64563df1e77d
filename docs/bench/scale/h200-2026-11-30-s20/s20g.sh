#!/usr/bin/env bash
# Session 20, call 7 (kind nvidia-h200, 16 cores): where a piece's index
# build spends its device time: the one call and the torus quarter
# (--memory-budget 22400) with RTHDIST_SUBMIT_TRACE, whose index-build
# submissions now list their phases (fill, keys, scan, scatter, heads,
# scan, cells, check); the traces kept (xz).
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
for r in 1 2; do
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline $S/a.ply $S/b.ply > $RES/call_$r.json 2> $RES/call_$r.trace
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline --memory-budget 22400 $S/a.ply $S/b.ply > $RES/q_$r.json 2> $RES/q_$r.trace
done
grep "between marks" $RES/call_2.trace | head -4
grep "between marks" $RES/q_2.trace | head -6
xz -9 $RES/*.trace
rm -f $S/*.ply
