#!/usr/bin/env bash
# Session 24, call 3 (one H200, 16 cores): per-point calls narrowed to the
# two cores whatever the strays (ba935de, "after") against cd967ba
# ("before"), alternated, two rounds, a process a run: 2M double points in
# a 5 cm cube beside one stray 2.5 km away, against 2M beside one 3.1 km
# away (session 23's pair); the same pair's h alone on rt-pipeline; then the
# engine tests the session touched, with the validation layer, on
# rt-pipeline.
BUNDLE=.devt
source tools/bench/device_prelude.sh
B=.devt/pp
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
run() {  # name, then the command
  local name=$1; shift
  timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
}
for r in 1 2; do
  for v in cd967 ba935; do
    for be in cpu rt-pipeline; do
      run stray-pp-$be-$v-$r $B/rthdist-$v /tmp/ca.ply /tmp/cb.ply --per-point --backend $be --json --quiet
    done
    run stray-h-rt-pipeline-$v-$r $B/rthdist-$v /tmp/ca.ply /tmp/cb.ply --backend rt-pipeline --json --quiet
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
        print(name, "no JSON", open(f[:-5] + ".err").read()[-300:]); continue
    t = j.get("timings_ms", {})
    pp = j.get("per_point") or {}
    c = j.get("counters", {})
    rows[name.rsplit("-", 1)[0]].append((t.get("total"), t.get("refine"), t.get("pieces"), j.get("hausdorff"),
        json.dumps(pp.get("hd95"), sort_keys=True), [c.get(k, {}).get("narrowed_targets") for k in ("a_to_b", "b_to_a")]))
for k in sorted(rows):
    v = rows[k]
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v],
          "pieces", [round(x[2] or 0, 1) for x in v], "H", sorted({x[3] for x in v}), "hd95", sorted({x[4] for x in v}), "narrowed", v[0][5])
PY
export VK_LAYER_PATH=$PWD/.devt/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 300 .devt/rthdist_engine_tests --gtest_filter='NarrowedTargets.*:ExactPerPoint.*:DeviceInput.*:PreparedSet.*:CallOptions.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/engine_tests.txt | tr '\n' ' ')"
