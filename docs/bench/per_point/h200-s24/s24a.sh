#!/usr/bin/env bash
# Session 24, call 2 (one H200, 16 cores): the exact pass's tree build
# (cpu/exact_nearest.cpp) with the top levels' medians selected on every
# worker and subtrees of 2^12 points (after) against 5edb842 (before),
# alternated, three rounds, a process a run: the Dragon pair read as doubles
# and a 2M double pair beside km strays (session 23's inputs), and 5M x 5M
# double points on two noisy spheres at UTM coordinates, per point.
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
for name, seed in (("sa", 3), ("sb", 4)):
    r = np.random.default_rng(seed)
    v = r.normal(size=(5000000, 3)); v /= np.linalg.norm(v, axis=1)[:, None]
    ply(f"/tmp/{name}.ply", at + 20.0 * v + r.normal(scale=0.01, size=v.shape))
PY
run() {  # name, then the command
  local name=$1; shift
  timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
}
for r in 1 2 3; do
  for v in before after; do
    bin=$B/rthdist-$v
    for be in cpu rt-pipeline; do
      run dragon-$be-$v-$r $bin $B/dragon_vrip.ply.gz .devt/m/dragon_vrip_res2.ply.gz --per-point --backend $be --json --quiet
    done
    run stray-cpu-$v-$r $bin /tmp/ca.ply /tmp/cb.ply --per-point --backend cpu --json --quiet
    run sphere-cpu-$v-$r $bin /tmp/sa.ply /tmp/sb.ply --per-point --backend cpu --json --quiet
    run sphere-rt-pipeline-$v-$r $bin /tmp/sa.ply /tmp/sb.ply --per-point --backend rt-pipeline --json --quiet
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
    rows[name.rsplit("-", 1)[0]].append((t.get("total"), t.get("refine"), j.get("hausdorff"), pp.get("hd95"), pp.get("mean")))
for k in sorted(rows):
    v = rows[k]
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v],
          "H", sorted({x[2] for x in v}), "hd95", sorted({x[3] for x in v}), "mean", sorted({x[4] for x in v}))
PY
