#!/usr/bin/env bash
# Session 19, call 4 (kind nvidia-h200-x2): the session's build (rthdist:
# the grid at 32 cells a side, the scatter's writer) against the session's
# start (rthdist-before, 340211b): the torus quarter and the one call beside
# it, 3 rounds each build, alternated; two devices; 1B x 1B on one and two
# devices. The first process after the files are read runs 1B slower in
# every call so far: the kernel's huge-page counters around it.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
for f in enabled defrag khugepaged/defrag; do echo "thp $f: $(cat /sys/kernel/mm/transparent_hugepage/$f)"; done
vm() { grep -E "^(compact_stall|compact_fail|compact_success|thp_fault_alloc|thp_fault_fallback) " /proc/vmstat | awk '{printf "%s=%s ", $1, $2}'; echo; }
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/$label.json 2> /tmp/res/$label.trace
  local rc=$?
  echo "$label rc=$rc $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'wall', round(t.get('wall',0)), 'pieces', round(t.get('pieces',0)), 'up', round(t.get('upload',0)), 'ix', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'chk', round(t.get('check',0)))" /tmp/res/$label.json 2>&1 | head -c 300) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)\|round one [0-9.]*\|proof [0-9.]*' /tmp/res/$label.trace | tr '\n' ' ')"
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
for r in 1 2 3; do
  one call_before_$r rthdist-before
  one call_after_$r rthdist
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
for r in 1 2; do
  one q_two_before_$r rthdist-before --memory-budget 22400 --devices 0,1
  one q_two_after_$r rthdist --memory-budget 22400 --devices 0,1
done
rm -f $S/*.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/a.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/b.ply & wait); sync; cat $S/*.ply > /dev/null
echo "vm before the first 1B process: $(vm)"
one 1B_after_1 rthdist
echo "vm after it: $(vm)"
one 1B_before_1 rthdist-before
echo "vm after the second: $(vm)"
one 1B_after_2 rthdist
one 1B_before_2 rthdist-before
one 1B_two_after_1 rthdist --devices 0,1
one 1B_two_before_1 rthdist-before --devices 0,1
