#!/usr/bin/env bash
# CPU backend, one-shot: the CLI (a process a run) and repeated one-shot
# calls in one process, before/after alternated.
K=$(cd "$(dirname "$0")" && pwd); OUT=$1; mkdir -p "$OUT"; I=$K/inputs
rows="bunny-res4:bunny armadillo-dec:armadillo dragon-res4:dragon bunny:bunny-t0.1 bunny:bunny-res2 dragon:dragon-res2"
for round in 1 2 3 4 5; do
  for r in $rows; do
    IFS=: read -r p m <<< "$r"
    for b in before after; do
      cli=$K/rthdist; [ $b = before ] && cli=$K/rthdist-before
      "$cli" "$I/$p.ply" "$I/$m.ply" --surface b --backend cpu --json 2>/dev/null | python3 -c "
import json,sys;d=json.load(sys.stdin);t=d['timings_ms'];print(json.dumps({'build':'$b','round':$round,'row':'$p>$m','kind':'cli','total':t['total'],'bvh':t.get('build'),'search':t.get('search'),'h':d.get('hausdorff') or d.get('directed',{}).get('distance')}))" >> "$OUT/split.jsonl"
    done
  done
done
for r in $rows; do
  IFS=: read -r p m <<< "$r"
  for b in before after; do
    sb=$K/rthdist-surface-bench; [ $b = before ] && sb=$K/rthdist-surface-bench-before
    "$sb" "$I/$p.ply" "$I/$m.ply" --backend cpu --runs 1 --warmup 1 --one-shot 9 --no-verify 2>/dev/null | sed "s/^{/{\"build\":\"$b\",\"kind\":\"oneshot\",/" >> "$OUT/oneshot.jsonl"
  done
done
