#!/usr/bin/env bash
# Session 22, call 4 (one H200, 16 cores; build 603cbd6): a scale row of
# the point-to-surface benchmark with Open3D beside it. 1M and 10M samples
# of dragon_vrip_res2's surface (tools/bench/sample_surface.py, seed 1)
# measured to dragon_vrip_res3's 47,794 triangles: Open3D 0.16
# RaycastingScene (scene built each run, and kept), CGAL 5.5's AABB tree
# (16 threads), rthdist's CPU backend and rt-pipeline on kept Engines
# (rthdist-surface-bench; the directed maximum, and --per-point: every
# point's distance, checked against the CPU backend's), and rt-pipeline
# one-shot (a device per call). Open3D runs from tools/bench/open3d_bundle.sh.
# Carried in two calls on one warm machine (64 MiB a call): the first copies
# .devo (the bundle's first part, the binaries and inputs) to .devkeep:
#   mkdir -p .devkeep && cp .devo/* .devkeep/
# the second carries .devp (the rest of the bundle) and runs this.
source tools/bench/device_prelude.sh
B=.devkeep
cat $B/part.aa .devp/part.ab .devp/part.ac | xz -d | tar xf - -C /tmp || exit 1
O3D=/tmp/open3d/run.sh
$O3D -c "import open3d, numpy; print('open3d', open3d.__version__, 'numpy', numpy.__version__)"
M=$B/dragon-res3.ply
for n in 1000000 10000000; do
  python3 tools/bench/sample_surface.py $B/dragon-res2.ply.gz $n 1 /tmp/r$n.ply || exit 1
done
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for n in 1000000 10000000; do
  P=/tmp/r$n.ply
  run o3d-$n $O3D tools/bench/surface_peers.py --open3d-worker $P $M 5
  run o3d-kept-$n $O3D tools/bench/surface_peers.py --open3d-worker $P $M 5 --open3d-kept
  run cgal-$n $B/surface-cgal points $P $M --threads 0 --repeat 3
  run gpu-$n $B/rthdist-surface-bench $P $M --backend rt-pipeline --runs 5 --warmup 1 --one-shot 3
  run gpu-pp-$n $B/rthdist-surface-bench $P $M --backend rt-pipeline --runs 5 --warmup 1 --per-point
  run cpu-$n $B/rthdist-surface-bench $P $M --backend cpu --runs 5 --warmup 1 --no-verify
  run cpu-pp-$n $B/rthdist-surface-bench $P $M --backend cpu --runs 5 --warmup 1 --no-verify --per-point
done
python3 - <<'PY'
import json, glob, os, statistics
R = "/tmp/res"
def med(v): return statistics.median(v)
for n in ("1000000", "10000000"):
    o = json.load(open(f"{R}/o3d-{n}.json")); ok = json.load(open(f"{R}/o3d-kept-{n}.json"))
    c = json.load(open(f"{R}/cgal-{n}.json"))
    print(n, "open3d med %.1f (%s) h %.17g" % (med(o["ms"]), [round(x) for x in o["ms"]], o["h"]),
          "| open3d kept %.1f" % med(ok["ms"]), "| cgal %.1f h %.17g" % (c["median_ms"], c["h"]))
    for k in ("gpu", "gpu-pp", "cpu", "cpu-pp"):
        j = json.load(open(f"{R}/{k}-{n}.json"))
        m = j["kept_median_ms"]
        print("  ", k, "kept total %.1f" % m["total"], "all", [round(x, 1) for x in j["kept_total_ms_all"]],
              "h %.17g" % j["hausdorff"], "agree", j["agree"], "one-shot", j.get("one_shot_median_ms", {}).get("total"),
              "ref", j.get("cpu_reference"), {x: round(y, 1) for x, y in m.items() if y})
PY
