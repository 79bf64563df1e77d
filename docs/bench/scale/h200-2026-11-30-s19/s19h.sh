#!/usr/bin/env bash
# Session 19, call 8 (kind nvidia-h200, 16 cores): scatter_floor.cpp again,
# its cells inlined as the library's are, and the buckets' groups 16 to 256
# points: do fewer places and longer runs of lines make the scatter cheaper
# on this host? 700M points, 16 threads, streaming stores and none.
set -uo pipefail
B=.devs; mkdir -p $OUT /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
nproc
./$B/scatter_floor 700000000 16 0 2 | tee /tmp/res/t16.txt
./$B/scatter_floor 700000000 16 3 1 | tee /tmp/res/t16_nowrite.txt
