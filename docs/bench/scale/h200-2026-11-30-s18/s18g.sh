#!/usr/bin/env bash
# Session 18, call 7 (kind nvidia-h200-x2, one device used): where the torus
# quarter's host time goes on the 32-core host (RTHDIST_SUBMIT_TRACE's
# pieces lines), 3 processes, and the one call beside it (build 30091d3).
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
for r in 1 2 3; do
  for mode in call quarter; do
    extra=""; [ $mode = quarter ] && extra="--memory-budget 22400"
    RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline $extra $S/a.ply $S/b.ply > /tmp/res/${mode}_$r.json 2> /tmp/trace.txt
    grep "rthdist pieces" /tmp/trace.txt > /tmp/res/${mode}_$r.pieces.txt
    echo "$mode $r submissions $(grep -c 'rthdist submit' /tmp/trace.txt) $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'check', round(t.get('check',0)), '| gpu upload', round(g['upload']), 'index', round(g['index']), 'cull', round(g['cull']))" /tmp/res/${mode}_$r.json)"
    cat /tmp/res/${mode}_$r.pieces.txt
  done
done
