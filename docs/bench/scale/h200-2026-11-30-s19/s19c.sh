#!/usr/bin/env bash
# Session 19, call 3 (kind nvidia-h200-x2): the last pieces in space
# gathered beside round one's calls (rthdist, default on a GPU) against
# 856917b (rthdist-before: the grid at 32 cells a side) and against the same
# build with RTHDIST_SCATTER_BESIDE_CALLS=0 (the new writer alone): the torus
# quarter alternated 3 rounds with the one call beside it, then 1B x 1B 2
# rounds, one device; then two devices. `sync` after generating the files
# (the first process after them ran slow in calls 1-2: their writeback).
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label env binary args...
  local label=$1 envv=$2 bin=$3; shift 3
  env $envv RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/res/$label.trace
  local rc=$?
  echo "$label rc=$rc $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'up', round(t.get('upload',0)), 'ix', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'chk', round(t.get('check',0)))" /tmp/res/$label.json 2>&1 | head -c 300) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*[^)]*)\|round one [0-9.]*\|proof [0-9.]*' /tmp/res/$label.trace | tr '\n' ' ')"
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
for r in 1 2 3; do
  one call_$r X=1 rthdist
  one q_before_$r X=1 rthdist-before --memory-budget 22400
  one q_after_$r X=1 rthdist --memory-budget 22400
  one q_off_$r RTHDIST_SCATTER_BESIDE_CALLS=0 rthdist --memory-budget 22400
done
for r in 1 2; do
  one q_two_before_$r X=1 rthdist-before --memory-budget 22400 --devices 0,1
  one q_two_after_$r X=1 rthdist --memory-budget 22400 --devices 0,1
done
rm -f $S/*.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/a.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
for r in 1 2; do
  one 1B_before_$r X=1 rthdist-before
  one 1B_after_$r X=1 rthdist
done
one 1B_two_before_1 X=1 rthdist-before --devices 0,1
one 1B_two_after_1 X=1 rthdist --devices 0,1
