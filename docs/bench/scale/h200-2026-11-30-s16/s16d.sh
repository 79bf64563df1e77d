#!/usr/bin/env bash
# Session 16: the surface rows again (per-point and one-shot), before/after alternated, 3 rounds.
set -uo pipefail
B=.devp; D=$B/data; S=/tmp/rthdist-samples; here=tools/bench; mkdir -p $S $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
source $here/gpu_rows.sh
for round in 1 2 3; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for c in "${cases[@]}"; do set -- $c
    case $1 in surface-*) ;; *) continue ;; esac
    for pp in "" --per-point; do
      $bin "$2" "$3" --name "$1" --backend rt-pipeline --runs 7 --warmup 2 $pp 2>> $OUT/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; d['per_point']='$pp'!=''; print(json.dumps(d))" >> $OUT/rows2.jsonl
    done
  done
done; done
python3 - $OUT/rows2.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d['case'],d['per_point'],d['build'])].append(d)
for (n,pp,b),v in sorted(rows.items()):
    print(n, 'per-point' if pp else 'one-shot', b, [(round(x['median_ms']['wall'],2), round(x['median_ms']['check'],2)) for x in v])
PY
