#!/usr/bin/env bash
# Kept rt-pipeline Engine per points row: the default route vs descending only
# (RTHDIST_SURFACE_DESCEND=1; the tail's tree kept after the warm-up).
B=$(cd "$(dirname "$0")" && pwd); OUT=$1; mkdir -p "$OUT"
rows="bunny>res2:bunny:bunny-res2 bunny>res3:bunny:bunny-res3 bunny>res4:bunny:bunny-res4 bunny-res4>bunny:bunny-res4:bunny dragon>res2:dragon:dragon-res2 dragon>res3:dragon:dragon-res3 dragon>res4:dragon:dragon-res4 dragon-res4>dragon:dragon-res4:dragon armadillo>dec:armadillo:armadillo-dec armadillo-dec>armadillo:armadillo-dec:armadillo scans>bunny:bunny-scans:bunny bunny>t0.1:bunny:bunny-t0.1 bunny>t0.01:bunny:bunny-t0.01 bunny>t0.001:bunny:bunny-t0.001"
for round in 1 2; do
for r in $rows; do
  IFS=: read -r name p m <<< "$r"
  for mode in default descend; do
    env=(); [ $mode = descend ] && env=(RTHDIST_SURFACE_DESCEND=1)
    env "${env[@]}" "$B/rthdist-surface-bench" "$B/inputs/$p.ply" "$B/inputs/$m.ply" --backend rt-pipeline --runs 7 --warmup 2 --no-verify --name "$name" 2>>"$OUT/err.txt" | sed "s/^{/{\"mode\":\"$mode\",\"round\":$round,/" >> "$OUT/probe.jsonl"
  done
done
done
