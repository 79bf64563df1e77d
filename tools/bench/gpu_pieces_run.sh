#!/usr/bin/env bash
# Out of core on a lent GPU (issue 33), one call: the torus 300M x 400M in one
# call and under a forced budget of a quarter of its one-call memory
# (--memory-budget 22400 MiB), the build before and after alternated, then the
# 1B x 1B torus (past one device's memory) on the device(s) given.
#
#   tools/bench/gpu_pieces_run.sh BUNDLE OUTDIR
#
# BUNDLE holds rthdist (after), rthdist-pieces-before (before) and
# rthdist-scale-gen. Environment: RUNS (processes of the after build per
# budget case, default 3), BEFORE (processes of the before build, default 1),
# VERIFY (1: one more after process with --verify, default 1), BIG (1: also
# the 1B x 1B torus, default 1), BIG_RUNS (default 2), DEVICES (e.g. "0,1":
# the budget case and the 1B x 1B also on these devices), BIG_BEFORE (1:
# each 1B x 1B process of the after build preceded by one of the before
# build, default 0), ALT_ENV (e.g.
# "RTHDIST_HOST_IMPORT=1": every process of the after build is followed by
# one with these variables set, labelled "+ALT_ENV"), TRACE (1: every
# process with RTHDIST_SUBMIT_TRACE=1, its stderr kept beside its JSON),
# SCRATCH (default /tmp/rthdist-scale).
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd)
OUT=${2:?out dir}
S=${SCRATCH:-/tmp/rthdist-scale}
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
source "$here/scale_cases.sh"
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null; nproc; } > "$OUT/machine.txt"
cat "$OUT/machine.txt"
n=0
trace=()
[ "${TRACE:-0}" = 1 ] && trace=(RTHDIST_SUBMIT_TRACE=1)
run1() {  # run1 LABEL BIN ENV ARGS... : one process, one line
  local label=$1 bin=$2 extra=$3
  shift 3
  n=$((n + 1))
  local t0
  t0=$(date +%s%N)
  # shellcheck disable=SC2086  # extra: variable assignments, one word each
  env "${trace[@]}" $extra "$B/$bin" --json --quiet --backend rt-pipeline "$@" "${files[@]}" > "$OUT/$n.json" 2> "$OUT/$n.err"
  local rc=$?
  echo "$label: exit $rc in $(( ($(date +%s%N) - t0) / 1000000 )) ms"
  python3 "$here/scale_line.py" "$label" "$n" "$rc" "$OUT/$n.json" "$OUT/$n.err"
}
run() {  # run LABEL BIN ARGS... : one process (and one with ALT_ENV for the after build)
  local label=$1 bin=$2
  shift 2
  run1 "$label" "$bin" "" "$@"
  [ -n "${ALT_ENV:-}" ] && [ "$bin" = rthdist ] && run1 "$label +$ALT_ENV" "$bin" "$ALT_ENV" "$@"
  return 0
}
scale_specs torus-300x400
scale_files "$B" "$S"
cat "${files[@]}" > /dev/null
run "torus one call (after)" rthdist
for r in $(seq 1 "${RUNS:-3}"); do
  [ "$r" -le "${BEFORE:-1}" ] && run "torus budget 22400 (before)" rthdist-pieces-before --memory-budget 22400
  run "torus budget 22400 (after)" rthdist --memory-budget 22400
  [ -n "${DEVICES:-}" ] && run "torus budget 22400 (after, devices $DEVICES)" rthdist --memory-budget 22400 --devices "$DEVICES"
done
[ "${VERIFY:-1}" = 1 ] && run "torus budget 22400 (after, --verify)" rthdist --memory-budget 22400 --verify
rm -f "${files[@]}"
if [ "${BIG:-1}" = 1 ]; then
  scale_specs torus-1000x1000
  scale_files "$B" "$S"
  cat "${files[@]}" > /dev/null
  for r in $(seq 1 "${BIG_RUNS:-2}"); do
    [ "${BIG_BEFORE:-0}" = 1 ] && run "torus 1B x 1B (before)" rthdist-pieces-before
    run "torus 1B x 1B (after)" rthdist
    [ -n "${DEVICES:-}" ] && run "torus 1B x 1B (after, devices $DEVICES)" rthdist --devices "$DEVICES"
  done
  rm -f "${files[@]}"
fi
