#!/usr/bin/env bash
# Session 32, call 1 (kind nvidia-h200: one H200, 16 cores): the partition's
# fresh memory. RTHDIST_PIECES_PREFAULT (an experiment's switch in this
# build): 0 as before; 1 the gathered arrays' pages cleared within the keys
# pass (each range its share, 2 MiB at a time between its runs); 2 in a pass
# of their own before it. pieces-bench on the torus 300M x 400M under the
# quarter's budget, then the CLI: the one call and the quarter in each mode,
# alternated, 3 rounds.
BUNDLE=.dev32
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B
for f in rthdist pieces-bench rthdist-scale-gen; do xz -dc .dev32/$f.xz > $B/$f; chmod +x $B/$f; done
source tools/bench/scale_cases.sh
S=/tmp/scale; mkdir -p $S
scale_specs torus-300x400; scale_files $B $S; cat "${files[@]}" > /dev/null
grep -i "AnonHuge" /proc/meminfo; cat /sys/kernel/mm/transparent_hugepage/enabled; uname -r
for r in 1 2; do
  for m in 0 1 2; do
    RTHDIST_PIECES_PREFAULT=$m $B/pieces-bench "${files[@]}" --budget-mib 22400 --runs 2 > $RES/pb_m${m}_$r.json 2>&1
    echo "pb m$m r$r $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(d['pieces'], d['hash'], {k: round(v) for k, v in d['median_ms'].items()}, d['scatter_all'])" $RES/pb_m${m}_$r.json 2>&1 | head -c 300)"
  done
done
one() {  # label mode args...
  local label=$1 mode=$2; shift 2
  RTHDIST_PIECES_PREFAULT=$mode RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" "${files[@]}" > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'up', round(t['upload']), 'idx', round(t['index']), 'cull', round(t['cull']), 'gpu', round(g['upload']), round(g['index']), round(g['cull']))" $RES/$label.json 2>&1 | head -c 300) | $(grep -o 'partition [0-9.]* ms (box [0-9.]*, fault [0-9.]*, keys [0-9.]*, plan [0-9.]*, scatter [0-9.]*)' $RES/$label.trace)"
  grep -v "^rthdist submit\|^rthdist buffer" $RES/$label.trace > $RES/$label.pieces.txt; rm $RES/$label.trace
}
one warm 0
for r in 1 2 3; do
  one call_$r 0
  for m in 0 1 2; do one q_m${m}_$r $m --memory-budget 22400; done
done
