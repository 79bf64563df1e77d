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
# Environment: PROCS (default 2), VERIFY (default 1; 0: no --verify, for the
# CLI's wall time alone: the CPU check costs 10-45 s a case), BEFORE (a
# previous build's rthdist: each process of the new one is preceded by one of
# it on the same inputs, files and lines tagged "before"), EXTRA (more
# rthdist options, e.g. "--memory-budget 20000"), SCRATCH (where the inputs
# go; default /tmp/rthdist-scale).
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
    verify=--verify
    [ "${VERIFY:-1}" = 0 ] && verify=
    builds=(new)
    [ -n "${BEFORE:-}" ] && builds=(before new)
    for build in "${builds[@]}"; do
      bin=$B/rthdist name=$c
      [ "$build" = before ] && bin=$BEFORE name=$c.before
      t0=$(date +%s%N)
      # shellcheck disable=SC2086
      "$bin" --json $verify --quiet --backend rt-pipeline ${EXTRA:-} "${files[@]}" \
        > "$OUT/$name.$p.json" 2> "$OUT/$name.$p.err"
      rc=$?
      echo "$name process $p: exit $rc in $(( ($(date +%s%N) - t0) / 1000000 )) ms" >> "$OUT/log.txt"
      python3 "$here/scale_line.py" "$name" "$p" "$rc" "$OUT/$name.$p.json" "$OUT/$name.$p.err" | tee -a "$OUT/lines.txt"
    done
  done
  rm -f "${files[@]}"
done
cat "$OUT/log.txt"
