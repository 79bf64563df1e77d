#!/usr/bin/env bash
# Density rows of issue 17 on the device machine (NVIDIA driver, no Vulkan
# loader: see docs/gpu.md), beside CuPy's KDTree, plus an A/B of the earlier
# rows of docs/bench/gpu.md against the previous build.
#   tools/bench/gpu_density_run.sh BUNDLE OUTDIR [ROWS...]
# ROWS: density.py's names (issue 33's far-* and crowded-* rows included).
# BEFORE=path: a previous rthdist-bench, run on each row alternated with the
# new one (3 rounds, lines tagged "build"); AB=0 skips the A/B of the earlier
# rows of docs/bench/gpu.md at the end; PEERS=0 skips CuPy.
# BUNDLE: rthdist, rthdist-bench (new), prev/rthdist-bench (previous build),
# data/dragon_vrip{,_res2}.ply.gz, ddata/ laid out like ../shared/data
# (lidar/FSite8_*-utm.ply, stanford/dragon/*.ply.gz).
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; shift 2
W=/tmp/rthdist-density-work; S=/tmp/rthdist-samples
mkdir -p "$OUT" "$W" "$S"
here=$(cd "$(dirname "$0")" && pwd)
rows=("$@")
[ ${#rows[@]} -gt 0 ] || rows=(cluster-200k cluster-1M cluster-5M cauchy-200k cauchy-1M lidar-fsite8-stray dragon-far-vertex)
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/machine.txt"
nproc >> "$OUT/machine.txt"

python3 - "$here" "$B/ddata" "$W" "${rows[@]}" <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[4:]:
    density.prepare(r, sys.argv[2], sys.argv[3])
PY
for r in "${rows[@]}"; do
  echo "== $r" >> "$OUT/verify.txt"
  timeout 300 "$B/rthdist" "$W/${r}_a.ply" "$W/${r}_b.ply" --backend rt-pipeline --verify >> "$OUT/verify.txt" 2>&1
  echo "exit $?" >> "$OUT/verify.txt"
  if [ -n "${BEFORE:-}" ]; then
    for round in 1 2 3; do
      for ver in before new; do
        bin=$B/rthdist-bench; [ $ver = before ] && bin=$BEFORE
        timeout 300 "$bin" "$W/${r}_a.ply" "$W/${r}_b.ply" --backend rt-pipeline --name "$r" \
          --runs 7 --warmup 3 --no-verify | sed "s/^{/{\"build\":\"$ver\",\"round\":$round,/" \
          >> "$OUT/density_rthdist.jsonl" 2>> "$OUT/errors.txt"
      done
    done
  else
    timeout 300 "$B/rthdist-bench" "$W/${r}_a.ply" "$W/${r}_b.ply" --backend rt-pipeline --name "$r" \
      --runs 7 --warmup 3 --no-verify >> "$OUT/density_rthdist.jsonl" 2>> "$OUT/errors.txt"
  fi
done
[ "${PEERS:-1}" = 0 ] || (cd "$here" && timeout 600 python3 gpu_density_peers.py "$W" "${rows[@]}" --runs 5) \
  >> "$OUT/density_peers.jsonl" 2>> "$OUT/errors.txt"

[ "${AB:-1}" = 0 ] && exit 0
# Earlier rows, previous build vs this one, alternating (3 rounds).
D=$B/data
python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" 1000000 1 "$S/s1m_a.ply" &
python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" 1000000 2 "$S/s1m_b.ply" &
python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" 5000000 3 "$S/s5m_a.ply" &
python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" 5000000 4 "$S/s5m_b.ply" &
python3 - "$D/dragon_vrip.ply.gz" "$S" "$here" <<'PY' &
import sys; sys.path.insert(0, sys.argv[3])
from ply_points import read_ply, write_ply
a = read_ply(sys.argv[1])
b = a.copy(); b[:, 0] += (float(a[:, 0].max()) - float(a[:, 0].min())) * 0.5
write_ply("%s/dragon_t0.5.ply" % sys.argv[2], b)
PY
wait
cases=("dragon-res2 $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz"
       "dragon-t0.5 $D/dragon_vrip.ply.gz $S/dragon_t0.5.ply"
       "surface-1M $S/s1m_a.ply $S/s1m_b.ply"
       "surface-5M $S/s5m_a.ply $S/s5m_b.ply")
for round in 1 2 3; do
  for ver in prev new; do
    bin=$B/rthdist-bench; [ $ver = prev ] && bin=$B/prev/rthdist-bench
    for c in "${cases[@]}"; do
      set -- $c
      timeout 120 "$bin" "$2" "$3" --backend rt-pipeline --name "$1" --runs 7 --warmup 3 --no-verify \
        | sed "s/^{/{\"build\":\"$ver\",\"round\":$round,/" >> "$OUT/ab.jsonl" 2>> "$OUT/errors.txt"
    done
  done
done
