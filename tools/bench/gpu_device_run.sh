#!/usr/bin/env bash
# Runs the GPU benchmark cases of docs/bench/gpu.md on a machine with an
# NVIDIA driver but no Vulkan loader (the `device` machine): see docs/gpu.md.
#   tools/bench/gpu_device_run.sh BUNDLE OUTDIR
# BUNDLE holds rthdist, rthdist-bench and data/dragon_vrip{,_res2}.ply.gz.
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; D=$B/data; S=/tmp/rthdist-samples
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/machine.txt"
"$B/rthdist" --list-devices >> "$OUT/machine.txt" 2>&1
date -u +%FT%TZ >> "$OUT/machine.txt"

# The rows of docs/bench/gpu.md: their inputs and `cases`.
source "$here/gpu_rows.sh"
echo "[" > "$OUT/cases.json"; sep=""
for c in "${cases[@]}"; do
  set -- $c
  echo "== $1" >> "$OUT/verify.txt"
  "$B/rthdist" "$2" "$3" --verify >> "$OUT/verify.txt" 2>&1; echo "exit $?" >> "$OUT/verify.txt"
  "$B/rthdist-bench" "$2" "$3" --name "$1" --runs 7 --warmup 3 >> "$OUT/rthdist.jsonl" 2>> "$OUT/errors.txt"
  printf '%s{"name":"%s","a":"%s","b":"%s"}\n' "$sep" "$1" "$2" "$3" >> "$OUT/cases.json"; sep=","
done
echo "]" >> "$OUT/cases.json"
# Radius growth and bit count sweeps (3 runs each, no CPU check).
for c in "${cases[@]:1:3}"; do
  set -- $c
  for g in 1.5 3 4; do
    "$B/rthdist-bench" "$2" "$3" --name "$1" --growth $g --runs 3 --warmup 1 --no-verify >> "$OUT/sweep.jsonl" 2>> "$OUT/errors.txt"
  done
done
for c in "${cases[@]:0:3}"; do
  set -- $c
  for k in 4 5 6 7 8; do
    "$B/rthdist-bench" "$2" "$3" --name "$1" --bits $k --runs 3 --warmup 1 --no-verify >> "$OUT/sweep.jsonl" 2>> "$OUT/errors.txt"
  done
done
# Per-point distances (every query's exact NN, no early break).
for c in "${cases[@]:0:3}"; do
  set -- $c
  "$B/rthdist-bench" "$2" "$3" --name "$1" --per-point --runs 5 --warmup 2 >> "$OUT/per_point.jsonl" 2>> "$OUT/errors.txt"
done
(cd "$here" && python3 gpu_peers.py "$OUT/cases.json" 5) >> "$OUT/peers.jsonl" 2>> "$OUT/errors.txt"
