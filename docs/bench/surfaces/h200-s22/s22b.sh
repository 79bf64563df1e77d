#!/usr/bin/env bash
# (The build after 5a4bf32: per-point arrays sized on several threads, distances only for --eval, the slivers grid; 5 rounds, no CGAL.)
# Session 22, call 2 (one H200, 16 cores): per-point distances to a surface
# on the GPU (rt-pipeline) against the CPU backend (16 threads) and CGAL's
# AABB tree (16 threads, every point's closest point), on samples of the
# Dragon's surface (tools/bench/sample_surface.py, seeds 1 and 2) measured
# to dragon_vrip_res2's triangles; the evaluation summary (--eval) alike;
# first the surface GPU tests with the validation layer.
source tools/bench/device_prelude.sh
B=.devs
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_gpu_surface_tests > $RES/surface_tests.txt 2>&1; echo "surface tests exit $?"
grep -E "^\[  (PASSED|FAILED) |tests ran|entries not|recomputed on" $RES/surface_tests.txt | tail -6
unset VK_LAYER_PATH
M=$B/data/dragon-res2.ply
for n in 1000000 10000000; do
  python3 tools/bench/sample_surface.py $B/data/dragon_vrip.ply.gz $n 1 /tmp/d$n.ply || exit 1
done
ls -la /tmp/d*.ply
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 120 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for r in 1 2 3 4 5; do
  for n in 1000000 10000000; do
    for b in cpu rt-pipeline; do
      run pp-$n-$b-$r $B/rthdist /tmp/d$n.ply $M --surface b --backend $b --per-point --json
      [ $r = 1 ] && run plain-$n-$b-$r $B/rthdist /tmp/d$n.ply $M --surface b --backend $b --json
      run eval-$n-$b-$r $B/rthdist /tmp/d$n.ply $M --surface b --backend $b --eval 0.0002,0.0005 --json
    done
  done
done
python3 - <<'PY'
import json, glob, os, statistics
R = os.environ.get("RES", "/tmp/res")
rows = {}
for f in sorted(glob.glob(R + "/*.json")):
    name = os.path.basename(f)[:-5]
    if name.startswith("cgal"):
        continue
    try:
        j = json.load(open(f))
    except Exception as e:
        print(name, "unreadable", e); continue
    kind, n, b, r = name.split("-", 3)[0], name.split("-")[1], "-".join(name.split("-")[2:-1]), name.split("-")[-1]
    t = j["timings_ms"]
    st = t.get("stages", {})
    key = (kind, n, b)
    rows.setdefault(key, []).append((t.get("total", t.get("evaluate")), t["wall"], st.get("gpu", 0), st.get("certify", 0), st.get("per_point", 0), j.get("hausdorff"), (j.get("per_point") or {}).get("tolerance"), (j.get("counters") or {}).get("a_to_b", {}).get("host_triangles"), json.dumps(j.get("eval", {}).get("thresholds", ""))[:160]))
for k in sorted(rows):
    v = rows[k]
    print(k, "total/evaluate med %.1f" % statistics.median(x[0] for x in v), "wall med %.1f" % statistics.median(x[1] for x in v), "gpu %.1f certify %.1f per_point %.1f" % (statistics.median(x[2] for x in v), statistics.median(x[3] for x in v), statistics.median(x[4] for x in v)), "h", v[0][5], "tol", v[0][6], "host_tri", v[0][7], v[0][8])
PY
for f in $RES/cgal-*.json; do echo "$f: $(head -c 600 $f)"; done
