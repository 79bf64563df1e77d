#!/usr/bin/env bash
# Prepared sets and batches on the `device` machine (docs/gpu.md):
#   tools/bench/gpu_prepared_run.sh BUNDLE OUTDIR
# BUNDLE holds rthdist-prepared-bench, rthdist_engine_tests, layers/ (the
# Khronos validation layer) and data/ (dragon_vrip{,_res2}.ply.gz,
# bun_zipper.ply, armadillo.off, igea.glb).
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; D=$B/data; S=/tmp/rthdist-samples
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/machine.txt"
date -u +%FT%TZ >> "$OUT/machine.txt"
(VK_LAYER_PATH=$B/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 240 "$B/rthdist_engine_tests" \
  > "$OUT/engine_tests.txt" 2>&1; echo "exit $?" >> "$OUT/engine_tests.txt")
for spec in "1000000 1 s1m_a" "1000000 2 s1m_b" "5000000 3 s5m_a" "5000000 4 s5m_b"; do
  set -- $spec
  python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" "$1" "$2" "$S/$3.ply" &
done
wait
bench="$B/rthdist-prepared-bench --backend rt-pipeline --runs 7 --warmup 3"
# A fresh pipeline cache: the first Engine compiles (cache "none"), the next ones load it.
rm -rf /tmp/rthdist-pcache; export RTHDIST_CACHE_DIR=/tmp/rthdist-pcache
$bench pair "$D/dragon_vrip.ply.gz" "$D/dragon_vrip_res2.ply.gz" --name dragon-res2-cold-cache >> "$OUT/pairs.jsonl"
$bench pair "$D/dragon_vrip.ply.gz" "$D/dragon_vrip_res2.ply.gz" --name dragon-res2 >> "$OUT/pairs.jsonl"
ls -la /tmp/rthdist-pcache >> "$OUT/machine.txt"
for t in 0.3 0.5 0.7; do
  $bench pair "$D/dragon_vrip.ply.gz" "$D/dragon_vrip.ply.gz" --translate $t --name dragon-t$t >> "$OUT/pairs.jsonl"
done
$bench pair "$S/s1m_a.ply" "$S/s1m_b.ply" --name surface-1M >> "$OUT/pairs.jsonl"
$bench pair "$S/s5m_a.ply" "$S/s5m_b.ply" --name surface-5M >> "$OUT/pairs.jsonl"
models="$D/dragon_vrip_res2.ply.gz $D/bun_zipper.ply $D/armadillo.off $D/igea.glb"
$bench batch $models --pairs 400 --min 2000 --max 10000 --seed 1 >> "$OUT/batch.jsonl"
