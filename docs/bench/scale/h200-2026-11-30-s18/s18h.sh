#!/usr/bin/env bash
# Session 18, call 8 (kind nvidia-h200-x2, one device): the first floor's
# sample cheapest-first (after) against 30091d3 (before, the strided 1024):
# the torus quarter (--memory-budget 22400) alternated 3 rounds with the
# one call beside it, then 1B x 1B, 2 rounds; RTHDIST_SUBMIT_TRACE's pieces
# lines kept.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/trace.txt
  local rc=$?
  grep "rthdist pieces" /tmp/trace.txt | grep -o "partition [0-9.]* ms\|round one [0-9.]*\|first floors.*" | tr '\n' ' ' > /tmp/res/$label.pieces.txt
  echo "$label rc=$rc $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'check', round(t.get('check',0)))" /tmp/res/$label.json 2>&1 | head -c 300) | $(cat /tmp/res/$label.pieces.txt)"
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
one call_0 $B/rthdist
for r in 1 2 3; do
  one quarter_before_$r $B/rthdist-before --memory-budget 22400
  one quarter_after_$r $B/rthdist --memory-budget 22400
done
rm -f $S/*.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/a.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/b.ply & wait); cat $S/*.ply > /dev/null
for r in 1 2; do
  one 1B_before_$r $B/rthdist-before
  one 1B_after_$r $B/rthdist
done
