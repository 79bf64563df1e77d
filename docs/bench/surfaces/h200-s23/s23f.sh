#!/usr/bin/env bash
# Session 23, call 8 (one H200, 16 cores; call 7 only copied Open3D's first
# part to /tmp/keep: `mkdir -p /tmp/keep && cp .devo/* /tmp/keep/`): the
# bunny's points rows on kept Engines, the CPU backend's queries in chunks
# of 256 (3ba5b4e, "before") against 16-256, about four a thread ("after"),
# alternated, two rounds; the rt-pipeline kept Engine (after) and Open3D
# 0.16's RaycastingScene (the scene built each run, 16 threads) in the same
# call.
source tools/bench/device_prelude.sh
K=/tmp/keep
Q=.devq
cat $K/part.aa .devp/part.ab .devp/part.ac | xz -d | tar xf - -C /tmp || exit 1
O3D=/tmp/open3d/run.sh
for row in "bunny bunny-res2" "bunny bunny-res3" "bunny bunny-res4" "bunny-res4 bunny"; do
  set -- $row
  P=$Q/$1.ply; M=$Q/$2.ply
  timeout 100 $O3D tools/bench/surface_peers.py --open3d-worker $P $M 9 > $RES/o3d-$1-$2.json 2> $RES/o3d-$1-$2.err
  for r in 1 2; do
    for v in before after; do
      timeout 100 $Q/sb-$v $P $M --backend cpu --runs 9 --warmup 2 --no-verify > $RES/cpu-$v-$1-$2-$r.json 2> /dev/null
    done
  done
  timeout 100 $Q/sb-after $P $M --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/gpu-$1-$2.json 2> /dev/null
  python3 - "$1" "$2" <<'PY'
import json, statistics, sys
a, b = sys.argv[1], sys.argv[2]
R = "/tmp/res"
o = json.load(open(f"{R}/o3d-{a}-{b}.json"))
line = f"{a}>{b} open3d {statistics.median(o['ms']):.2f} {[round(x, 2) for x in o['ms']]}"
for name in (f"cpu-before-{a}-{b}-1", f"cpu-after-{a}-{b}-1", f"cpu-before-{a}-{b}-2", f"cpu-after-{a}-{b}-2", f"gpu-{a}-{b}"):
    j = json.load(open(f"{R}/{name}.json"))
    line += f" | {name.split('-' + a)[0]} {j['kept_median_ms']['total']:.2f} h {j['hausdorff']:.12g}"
print(line, "| o3d h", o["h"])
PY
done
