#!/usr/bin/env bash
# Session 15 (floors): the quarter --verify'd, then one H200 against two (same machine), quarter and 1B x 1B alternated.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S $OUT /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label args...
  local label=$1; shift
  env RTHDIST_SUBMIT_TRACE=1 $B/rthdist --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/"${label// /_}".json 2> /tmp/res/"${label// /_}".err
  echo "$label rc=$? $(grep -o 'partition [0-9.]* ms.*' /tmp/res/"${label// /_}".err | head -1)"
  rm -f /tmp/res/"${label// /_}".err
  python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
v=d.get('verify'); v=(v.get('agree'), v.get('max_abs_diff')) if isinstance(v,dict) else v
print('   H', d['hausdorff'], 'verify', v, 'cert', d['certificate']['a_to_b'].get('confirmed'), d['certificate']['b_to_a'].get('confirmed'), 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'wall', round(t['wall']), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'check', round(t.get('check',0)), '| gpu upload', round(g['upload']), 'index', round(g['index']), 'cull', round(g['cull']))" /tmp/res/"${label// /_}".json
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
for r in 1 2; do one "quarter one $r" --memory-budget 22400; one "quarter two $r" --memory-budget 22400 --devices 0,1; done
rm -f $S/*.ply
(./$B/rthdist-scale-gen torus 1000000000 61 $S/a.ply & ./$B/rthdist-scale-gen torus 1000000000 62 $S/b.ply & wait); cat $S/*.ply > /dev/null
one "1B warm"
for r in 1 2; do one "1B one $r"; one "1B two $r" --devices 0,1; done
