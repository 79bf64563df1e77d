#!/usr/bin/env bash
# Where the quarter's read-back ("check") goes: the per-submission trace of one process.
set -uo pipefail
B=.devp; S=/tmp/rthdist-scale; mkdir -p $S $OUT
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline --memory-budget 22400 $S/a.ply $S/b.ply > $OUT/q.json 2> $OUT/q.err
echo rc=$?; wc -l $OUT/q.err; head -c 3000 $OUT/q.err; echo; grep -c . $OUT/q.err
