#!/usr/bin/env bash
# Session 19, call 1 (kind nvidia-h200-x2): where the torus quarter's
# partition time goes on this host. One build of 340211b with three
# temporary knobs (not committed): RTHDIST_X_CELLCAP (the grid's cells an
# axis, 64 on main), RTHDIST_X_GROUPBITS (kBlockGroupBits, 12 on main),
# RTHDIST_X_PREFAULT (the scatter's arrays written once before it, timed
# apart). Also RTHDIST_HOST_IMPORT=1, --threads 16, two devices, 1B x 1B.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc; lscpu | grep -i "model name\|thread\|L2\|L3\|socket" | tee /tmp/res/lscpu.txt
cat /sys/kernel/mm/transparent_hugepage/enabled
one() {  # label env... -- args...
  local label=$1; shift; local envs=(); while [ "$1" != "--" ]; do envs+=("$1"); shift; done; shift
  env "${envs[@]}" RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/res/$label.trace
  local rc=$?
  echo "$label rc=$rc $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'up', round(t.get('upload',0)), 'ix', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'chk', round(t.get('check',0)))" /tmp/res/$label.json 2>&1 | head -c 300) | $(grep -o 'prefault [0-9.]*\|partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)\|round one [0-9.]*' /tmp/res/$label.trace | tr '\n' ' ')"
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
one call_1 X=1 -- ; 
for r in 1 2; do
  one q_base_$r X=1 -- --memory-budget 22400
  one q_prefault_$r RTHDIST_X_PREFAULT=1 -- --memory-budget 22400
  one q_cap32_$r RTHDIST_X_CELLCAP=32 -- --memory-budget 22400
  one q_g10_$r RTHDIST_X_GROUPBITS=10 -- --memory-budget 22400
  one q_cap32g9_$r RTHDIST_X_CELLCAP=32 RTHDIST_X_GROUPBITS=9 -- --memory-budget 22400
  one q_import_$r RTHDIST_HOST_IMPORT=1 -- --memory-budget 22400
  one q_t16_$r X=1 -- --memory-budget 22400 --threads 16
done
one q_two_1 X=1 -- --memory-budget 22400 --devices 0,1
one call_2 X=1 -- 
rm -f $S/*.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/a.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/b.ply & wait); cat $S/*.ply > /dev/null
one 1B_base_1 X=1 --
one 1B_cap32g10_1 RTHDIST_X_CELLCAP=32 RTHDIST_X_GROUPBITS=10 --
one 1B_two_1 X=1 -- --devices 0,1
