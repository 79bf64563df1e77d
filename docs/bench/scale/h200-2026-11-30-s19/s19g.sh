#!/usr/bin/env bash
# Session 19, call 7 (kind nvidia-h200: the x2 kind was no longer lent):
# scatter_floor.cpp (built here: g++ -O2 -march=x86-64-v3 -pthread) on the
# 16-core host: what the partition's passes cost when they only move memory,
# 700M points, all 16 threads (streaming stores of 16 bytes; none: the loop
# alone) and 8; then fa8c6cf's torus quarter and the one call, 3 rounds.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nproc; lscpu | grep -i "model name"; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./$B/scatter_floor 700000000 16 0 | tee /tmp/res/t16.txt
./$B/scatter_floor 700000000 16 3 | tee /tmp/res/t16_nowrite.txt
./$B/scatter_floor 700000000 8 0 | tee /tmp/res/t8.txt
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
one() {  # label args...
  local label=$1; shift
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/res/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)))" /tmp/res/$label.json 2>&1 | head -c 200) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' /tmp/res/$label.trace)"
}
for r in 1 2 3; do
  one call_$r
  one q_$r --memory-budget 22400
done
