#!/usr/bin/env bash
# The final build (rthdist = 0bcdece) against the streaming scatter alone (rthdist-wc = 4bb4573), then the final --verify'd.
set -uo pipefail
B=.devp; S=/tmp/rthdist-scale; mkdir -p $S $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label bin args...
  local label=$1 bin=$2; shift 2
  env RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $OUT/"${label// /_}".json 2> /tmp/e.txt
  echo "$label rc=$? $(grep -o 'partition [0-9.]* ms.*' /tmp/e.txt | head -1)"
  python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; v=d.get('verify')
print('   H', d['hausdorff'], 'cert', d['certificate']['a_to_b'].get('confirmed'), d['certificate']['b_to_a'].get('confirmed'), 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'verify', v and (v['ok'], v['max_abs_diff']))" $OUT/"${label// /_}".json
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
for r in 1 2; do for v in rthdist-wc rthdist; do one "quarter $v $r" $v --memory-budget 22400; done; done
one "quarter final verify" rthdist --memory-budget 22400 --verify
