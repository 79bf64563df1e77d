#!/usr/bin/env bash
# Session 22, call 6 (one H200, 16 cores): the CPU backend's surface search
# before (the build of 5241456: input order, every leaf triangle measured)
# and after (942e986: queries in Morton order, a leaf triangle's own box
# test) against Open3D 0.16 in the same call, on call 4's scale row (1M and
# 10M samples of dragon_vrip_res2's surface to dragon_vrip_res3's 47,794
# triangles); kept Engines (rthdist-surface-bench), the directed value and
# --per-point, two rounds alternated; the GPU's kept Engine (--recycle)
# beside. Carried in two calls as s22d.sh (the first: mkdir -p /tmp/keep &&
# cp .devo/* /tmp/keep/).
source tools/bench/device_prelude.sh
K=/tmp/keep
cat $K/part.aa .devp/part.ab .devp/part.ac | xz -d | tar xf - -C /tmp || exit 1
O3D=/tmp/open3d/run.sh
M=$K/dragon-res3.ply
for n in 1000000 10000000; do
  python3 tools/bench/sample_surface.py $K/dragon-res2.ply.gz $n 1 /tmp/r$n.ply || exit 1
done
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for n in 1000000 10000000; do
  P=/tmp/r$n.ply
  run o3d-$n $O3D tools/bench/surface_peers.py --open3d-worker $P $M 5
  for r in 1 2; do
    for v in before after; do
      bin=$K/rthdist-surface-bench; [ $v = before ] && bin=.devp/rthdist-surface-bench-before
      run cpu-$v-$n-$r $bin $P $M --backend cpu --runs 5 --warmup 1 --no-verify
      run cpu-pp-$v-$n-$r $bin $P $M --backend cpu --runs 5 --warmup 1 --no-verify --per-point
    done
  done
  run gpu-$n $K/rthdist-surface-bench $P $M --backend rt-pipeline --runs 5 --warmup 1 --no-verify
  run gpu-pp-$n $K/rthdist-surface-bench $P $M --backend rt-pipeline --runs 5 --warmup 1 --per-point --recycle
done
python3 - <<'PY'
import json, glob, os, statistics
R = "/tmp/res"
for n in ("1000000", "10000000"):
    o = json.load(open(f"{R}/o3d-{n}.json"))
    print(n, "open3d med %.1f" % statistics.median(o["ms"]), [round(x) for x in o["ms"]], "h %.17g" % o["h"])
    for f in sorted(glob.glob(f"{R}/*-{n}*.json")):
        name = os.path.basename(f)[:-5]
        if name.startswith("o3d"): continue
        j = json.load(open(f))
        print("  ", name, "kept %.1f" % j["kept_median_ms"]["total"], [round(x, 1) for x in j["kept_total_ms_all"]], "h %.17g" % j["hausdorff"], "agree", j["agree"], j.get("cpu_reference", {}).get("per_point_within"))
PY
