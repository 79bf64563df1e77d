#!/usr/bin/env bash
# Session 23, calls 1-2 (one H200, 16 cores; call 1 ran without VK_LAYER_PATH,
# so its tests found no validation layer, and with the pass's queries in input order): the exact per-point pass
# (cpu/exact_nearest.hpp) and the thin triangles' 113-bit rule
# (core/point_triangle.cpp), the build of the session's start (3ba5b4e,
# "before") against this one ("after"), alternated, a process a run; then
# the GPU tests they touch with the validation layer on rt-pipeline.
source tools/bench/device_prelude.sh
B=.devs
D=$B/data
run() {  # name, then the command: its JSON in $RES/name.json, one line printed
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 240 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
# Inputs: 10M x 10M unit shells (float32), a 2M double cluster beside a 3 km
# stray in each set, 10M samples of the Dragon's surface (double).
$B/rthdist-scale-gen shell 10000000 61 /tmp/sa.ply > /dev/null && $B/rthdist-scale-gen shell 10000000 62 /tmp/sb.ply > /dev/null
python3 - <<'PY'
import numpy as np
at = np.array([512345.125, 5412345.5, 100.0])
def ply(path, p):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(p)}\nproperty double x\nproperty double y\nproperty double z\nend_header\n".encode())
        f.write(p.astype("<f8").tobytes())
for name, seed, far in (("ca", 1, 2500.0), ("cb", 2, 3100.0)):
    r = np.random.default_rng(seed)
    p = at + r.random((2000000, 3)) * 0.05  # 5 cm cube
    ply(f"/tmp/{name}.ply", np.vstack([p, at + [far, -far, 0.5 * far]]))
PY
python3 tools/bench/sample_surface.py $D/dragon_vrip.ply.gz 10000000 1 /tmp/s10m.ply || exit 1
for r in 1 2 3; do
  for v in before after; do
    bin=$B/rthdist; [ $v = before ] && bin=$B/rthdist-before
    for be in cpu rt-pipeline; do
      run dragon-$be-$v-$r $bin $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz --per-point --backend $be --json --quiet
      run shell-$be-$v-$r $bin /tmp/sa.ply /tmp/sb.ply --per-point --backend $be --json --quiet
      run stray-$be-$v-$r $bin /tmp/ca.ply /tmp/cb.ply --per-point --backend $be --json --quiet
      run surf-$be-$v-$r $bin /tmp/s10m.ply $D/dragon-res2.ply --surface b --per-point --backend $be --json --quiet
    done
  done
done
python3 - <<'PY'
import json, glob, os, collections
R = "/tmp/res"
rows = collections.defaultdict(list)
for f in sorted(glob.glob(f"{R}/*.json")):
    name = os.path.basename(f)[:-5]
    try:
        j = json.load(open(f))
    except Exception as e:
        print(name, "no JSON", e); continue
    t = j.get("timings_ms", {})
    c = j.get("counters", {}) or {}
    mended = [(c.get(k) or {}).get("per_point_mended") for k in ("a_to_b", "b_to_a")]
    h = j.get("hausdorff", j.get("a_to_b", {}).get("distance") if isinstance(j.get("a_to_b"), dict) else None)
    key = name.rsplit("-", 1)[0]
    rows[key].append((t.get("total"), t.get("refine"), t.get("wall"), h, mended, (j.get("per_point") or {}).get("hd95")))
for k, v in rows.items():
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v],
          "wall", [round(x[2] or 0, 1) for x in v], "h", v[0][3], "mended", v[0][4], "hd95", v[0][5])
PY
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 150 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "gpu surface tests exit $? $(grep -E 'PASSED|FAILED' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
timeout 200 $B/rthdist_engine_tests --gtest_filter='ExactPerPoint.*:NarrowedTargets.*:CallOptions.*:OutOfCore.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E 'PASSED|FAILED' $RES/engine_tests.txt | tr '\n' ' ')"
