#!/usr/bin/env bash
# Session 25, call 2 (one H200, 16 cores): where a kept GPU point-to-surface
# call's device time goes on small meshes. Variants of one build (f29f28e),
# alternated, two rounds of `rthdist-surface-bench --runs 9 --warmup 2`:
#   base   the build as it is (descend-only at most 4096 triangles)
#   fb     the BLAS built with PREFER_FAST_BUILD instead of PREFER_FAST_TRACE
#          (sb2/rb2: a temporary env knob RTHDIST_X_FASTBUILD, not in main)
#   radii  RTHDIST_SURFACE_DESCEND=0 (the radii's rays on any mesh)
#   fbr    fb and radii
#   desc   RTHDIST_SURFACE_DESCEND=1 (the tail's descent on any mesh)
# and the Dragon point-set rows (rthdist-bench, rt-pipeline) base vs fb.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx
M=$B/m
python3 tools/bench/sample_surface.py $M/dragon_vrip_res2.ply.gz 1000000 1 /tmp/s1m.ply > /dev/null || exit 1
python3 - <<'PY' || exit 1
import sys, numpy as np
sys.path.insert(0, "tools/bench")
from ply_points import read_ply, write_ply
v = read_ply(".devx/m/bun_zipper.ply").astype(np.float64)
rng = np.random.default_rng(1)
write_ply("/tmp/bunny10.ply", np.concatenate([v + rng.normal(0, 2e-4, v.shape) for _ in range(10)]).astype(np.float32))
write_ply("/tmp/bunny.ply", v.astype(np.float32))
write_ply("/tmp/dragon.ply", read_ply(".devx/m/dragon_vrip.ply.gz"))
PY
rows="bunny:bun_zipper_res2.ply bunny:bun_zipper_res3.ply bunny:bun_zipper_res4.ply bunny10:bun_zipper_res3.ply bunny10:bun_zipper_res4.ply dragon:dragon_vrip_res2.ply.gz dragon:dragon_vrip_res3.ply.gz dragon:dragon_vrip_res4.ply.gz s1m:dragon_vrip_res3.ply.gz"
run() {  # variant row-index a b
  local v=$1 i=$2 a=$3 b=$4 bin=$B/sb env=""
  case $v in fb) bin=$B/sb2; env="RTHDIST_X_FASTBUILD=1" ;; radii) env="RTHDIST_SURFACE_DESCEND=0" ;;
    fbr) bin=$B/sb2; env="RTHDIST_X_FASTBUILD=1 RTHDIST_SURFACE_DESCEND=0" ;; desc) env="RTHDIST_SURFACE_DESCEND=1" ;; esac
  env $env timeout 120 $bin $a $b --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/s$i-$v-$r.json 2> $RES/s$i-$v-$r.err
}
for r in 1 2; do
  i=0
  for row in $rows; do
    i=$((i + 1)); a=/tmp/${row%%:*}.ply; b=$M/${row##*:}
    for v in base fb radii fbr desc; do run $v $i $a $b; done
  done
  for t in 0 0.5; do
    for v in base fb; do
      bin=$B/rb2; env=""; [ $v = fb ] && env="RTHDIST_X_FASTBUILD=1"
      b=$M/dragon_vrip_res2.ply.gz; [ $t = 0.5 ] && b=/tmp/dragon.ply
      env $env timeout 120 $bin /tmp/dragon.ply $b --backend rt-pipeline --translate $t --runs 9 --warmup 3 --no-verify > $RES/p$t-$v-$r.json 2> $RES/p$t-$v-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys
R = "/tmp/res"
def get(f):
    try: return json.load(open(f))
    except Exception: return None
for i, row in enumerate(sys.argv[1].split(), 1):
    out, hs = row.replace(":", " > "), set()
    for v in ("base", "fb", "radii", "fbr", "desc"):
        parts = []
        for r in (1, 2):
            j = get(f"{R}/s{i}-{v}-{r}.json")
            if j is None: parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"])
            parts.append("%.3f [gpu %.3f build %.3f]" % (k["total"], k["gpu"], k["gpu_build"]))
        out += f"\n   {v:6s} " + " / ".join(parts)
    print(out, "\n   H", sorted(hs))
for t in ("0", "0.5"):
    for v in ("base", "fb"):
        parts = []
        for r in (1, 2):
            j = get(f"{R}/p{t}-{v}-{r}.json")
            if j is None: parts.append("-"); continue
            m = j["median_ms"]; parts.append("%.3f [index %.3f search %.3f gpu_sum %.3f gpu_index %.3f gpu_search %.3f] H %r" % (m["total"], m["index"], m["search"], m["gpu_sum"], m["gpu_index"], m["gpu_search"], j["hausdorff"]))
        print(f"dragon t{t} {v}: " + " || ".join(parts))
PY
