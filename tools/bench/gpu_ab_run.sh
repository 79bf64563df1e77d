#!/usr/bin/env bash
# A/B of two rthdist-prepared-bench builds on the `device` machine, in one
# session (machines differ by ~10% from session to session, so a before/after
# is measured side by side, alternating, never across sessions):
#   tools/bench/gpu_ab_run.sh BUNDLE OUTDIR
# BUNDLE holds rthdist-prepared-bench-before, rthdist-prepared-bench and
# data/ (dragon_vrip{,_res2}.ply.gz, bun_zipper.ply, armadillo.off, igea.glb).
# Writes OUTDIR/ab.jsonl: one line per (round, build, case), the bench's JSON
# with "build" and "round" added.
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; D=$B/data; S=/tmp/rthdist-samples
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
for spec in "1000000 1 s1m_a" "1000000 2 s1m_b" "5000000 3 s5m_a" "5000000 4 s5m_b"; do
  set -- $spec
  [ -f "$S/$3.ply" ] || python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" "$1" "$2" "$S/$3.ply" &
done
wait
export RTHDIST_CACHE_DIR=/tmp/rthdist-pcache
cases=("pair $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz --name dragon-res2"
       "pair $D/dragon_vrip.ply.gz $D/dragon_vrip.ply.gz --translate 0.5 --name dragon-t0.5"
       "pair $S/s1m_a.ply $S/s1m_b.ply --name surface-1M"
       "pair $S/s5m_a.ply $S/s5m_b.ply --name surface-5M"
       "batch $D/dragon_vrip_res2.ply.gz $D/bun_zipper.ply $D/armadillo.off $D/igea.glb --pairs 400 --min 2000 --max 10000 --seed 1")
for round in 1 2; do
  for build in before after; do
    bin=$B/rthdist-prepared-bench; [ $build = before ] && bin=$B/rthdist-prepared-bench-before
    for c in "${cases[@]}"; do
      # shellcheck disable=SC2086
      "$bin" --backend rt-pipeline --runs 7 --warmup 3 $c |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> "$OUT/ab.jsonl"
    done
  done
done
