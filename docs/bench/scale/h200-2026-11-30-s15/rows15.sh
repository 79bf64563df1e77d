#!/usr/bin/env bash
# Session 15: docs/bench/gpu.md's rows, 48c2235 (before) and d11385a (after) alternated, one-shot and per-point.
set -uo pipefail
B=.devo; D=$B/data; S=/tmp/rthdist-samples; here=$B/bench; mkdir -p $S $OUT
trap "tar czf $OUT/rows.tgz -C $OUT rows.jsonl errors.txt 2>/dev/null" EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
source $here/gpu_rows.sh
for round in 1 2; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for c in "${cases[@]}"; do set -- $c
    for pp in "" --per-point; do
      $bin "$2" "$3" --name "$1" --backend rt-pipeline --runs 5 --warmup 2 $pp 2>> $OUT/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; d['per_point']='$pp'!=''; print(json.dumps(d))" >> $OUT/rows.jsonl
    done
  done
done; done
python3 - $OUT/rows.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d.get('case'),d['per_point'],d['build'])].append(d)
for (n,pp,b),v in sorted(rows.items()):
    print(n, 'per-point' if pp else 'one-shot', b, [ (round(x['median_ms']['wall'],2), round(x['median_ms']['gpu_sum'],2)) for x in v], v[0].get('hausdorff'))
PY
