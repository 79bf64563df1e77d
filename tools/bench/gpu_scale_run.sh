#!/usr/bin/env bash
# The size cases of docs/bench/gpu.md (issue: wrong H at 300M x 400M points)
# on the device machine (docs/gpu.md): generates the samplings, runs
# `rthdist --json --verify` (the CPU backend on all cores checks the GPU
# result in the same process) and keeps each JSON and the wall time.
#   tools/bench/gpu_scale_run.sh BUNDLE OUTDIR CASE...
# CASE: torus-300x400 (noisy torus, 300M vs 400M points), sphere-400x400.
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; shift 2
S=/tmp/rthdist-scale; mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader > "$OUT/machine.txt"
"$B/rthdist" --list-devices --json >> "$OUT/machine.txt" 2>&1
for c in "$@"; do
  case $c in
    torus-300x400) specs=("torus 300000000 11" "torus 400000000 12") ;;
    sphere-400x400) specs=("sphere 400000000 21" "sphere 400000000 22") ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
  esac
  files=()
  t0=$(date +%s%N)
  for s in "${specs[@]}"; do
    set -- $s
    f="$S/$1_$2_$3.ply"; files+=("$f")
    [ -f "$f" ] || python3 "$here/scale_points.py" "$1" "$2" "$3" "$f" &
  done
  wait
  echo "$c: generated in $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> "$OUT/log.txt"
  t0=$(date +%s%N)
  "$B/rthdist" --json --verify --quiet --backend rt-pipeline "${files[@]}" > "$OUT/$c.json" 2> "$OUT/$c.err"
  echo "$c: exit $? in $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> "$OUT/log.txt"
  rm -f "${files[@]}"
done
cat "$OUT/log.txt"
