#!/usr/bin/env bash
# The scale suite (issue 32), for a lent GPU in one call (docs/gpu.md: build
# here, carry the bundle). Generates each case's seeded inputs on the device
# machine (rthdist-scale-gen, all cores, binary float PLY), runs
# `rthdist --json --verify --backend rt-pipeline` in PROCS processes per case
# (a value that changes between processes is a bug) and prints one line per
# process: H, both directed values, the certificate, the GPU stages, the wall
# time, and whether the CPU backend in the same process agreed.
#
#   tools/bench/gpu_scale_suite.sh BUNDLE OUTDIR [CASE...]
#
# BUNDLE holds rthdist and rthdist-scale-gen. Cases: tools/bench/scale_cases.sh
# (default: all but torus-1000x1000, which needs ~24 GB of disk and a long
# CPU check).
# Environment: PROCS (default 2), EXTRA (more rthdist options, e.g. "--memory-budget 20000"),
# SCRATCH (where the inputs go; default /tmp/rthdist-scale).
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd)
OUT=${2:?out dir}
shift 2
cases=("$@")
[ ${#cases[@]} -eq 0 ] && cases=(crowded-20M torus-300x400 shell-400x400 cluster-100M cube-300x300)
S=${SCRATCH:-/tmp/rthdist-scale}
PROCS=${PROCS:-2}
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
{
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null
  nproc
} > "$OUT/machine.txt"
source "$here/scale_cases.sh"
for c in "${cases[@]}"; do
  scale_specs "$c" || exit 2
  t0=$(date +%s%N)
  scale_files "$B" "$S"
  echo "$c generated in $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> "$OUT/log.txt"
  for p in $(seq 1 "$PROCS"); do
    # Read once before the first process: every process reads from the page cache.
    [ "$p" = 1 ] && cat "${files[@]}" > /dev/null
    t0=$(date +%s%N)
    # shellcheck disable=SC2086
    "$B/rthdist" --json --verify --quiet --backend rt-pipeline ${EXTRA:-} "${files[@]}" \
      > "$OUT/$c.$p.json" 2> "$OUT/$c.$p.err"
    rc=$?
    echo "$c process $p: exit $rc in $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> "$OUT/log.txt"
    python3 "$here/scale_line.py" "$c" "$p" "$rc" "$OUT/$c.$p.json" "$OUT/$c.$p.err" | tee -a "$OUT/lines.txt"
  done
  rm -f "${files[@]}"
done
cat "$OUT/log.txt"
