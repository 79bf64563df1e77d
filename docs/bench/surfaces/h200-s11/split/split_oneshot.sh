#!/usr/bin/env bash
K=$(cd "$(dirname "$0")" && pwd); OUT=$1; mkdir -p "$OUT"; I=${2:-$K/inputs}
rows="bunny-res4:bunny armadillo-dec:armadillo dragon-res4:dragon bunny:bunny-t0.1 bunny:bunny-res2 dragon:dragon-res2 bunny:bunny-res3 armadillo:armadillo-dec"
for round in 1 2 3; do
  for r in $rows; do
    IFS=: read -r p m <<< "$r"
    for b in before after; do
      sb=$K/rthdist-surface-bench; [ $b = before ] && sb=$K/rthdist-surface-bench-before
      "$sb" "$I/$p.ply" "$I/$m.ply" --backend cpu --runs 1 --warmup 1 --one-shot 9 --no-verify 2>/dev/null | sed "s/^{/{\"build\":\"$b\",\"round\":$round,/" >> "$OUT/oneshot.jsonl"
    done
  done
done
python3 - "$OUT/oneshot.jsonl" <<'PY'
import json,sys
rows={}
for l in open(sys.argv[1]):
    d=json.loads(l); m=d['one_shot_median_ms']; c=d['case'].split(' > ')
    key=c[0].split('/')[-1][:-4]+'>'+c[1].split('/')[-1][:-4]
    rows.setdefault(key,{}).setdefault(d['build'],[]).append((round(m['total'],2), round(m['build'],2), d['hausdorff']))
for k,v in rows.items():
    print(k, 'before', [x[:2] for x in v['before']], 'after', [x[:2] for x in v['after']], 'same h', len({x[2] for x in v['before']+v['after']})==1)
PY
