#!/usr/bin/env bash
# Does the pieces' index get slower because each piece's grid is finer? The quarter under auto bits and forced 7/6, and the one call.
set -uo pipefail
B=.devp; S=/tmp/rthdist-scale; mkdir -p $S $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label bin args...
  local label=$1 bin=$2; shift 2
  env RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $OUT/"${label// /_}".json 2> /tmp/e.txt
  echo "$label rc=$? $(grep -o 'partition [0-9.]* ms.*results [0-9.]* ms' /tmp/e.txt | head -1)"
  python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']; c=d['counters']
print('   H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'wall', round(t['wall']), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'check', round(t.get('check',0)), '| gpu upload', round(g['upload']), 'index', round(g['index']), 'cull', round(g['cull']), 'search', round(g['search']), 'refine', round(g['refine']), '| bits', c['a_to_b']['bits'], c['b_to_a']['bits'], 'cells', c['a_to_b']['occupied_cells'], c['b_to_a']['occupied_cells'], 'surv', c['a_to_b']['surviving_queries'], c['b_to_a']['surviving_queries'])" $OUT/"${label// /_}".json
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
one "one auto" rthdist
one "one bits7" rthdist --bits 7
for r in 1 2; do
  one "quarter auto $r" rthdist --memory-budget 22400
  one "quarter bits7 $r" rthdist --memory-budget 22400 --bits 7
  one "quarter bits6 $r" rthdist --memory-budget 22400 --bits 6
done
