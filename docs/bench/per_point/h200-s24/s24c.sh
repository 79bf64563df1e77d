#!/usr/bin/env bash
# Session 24, call 4 (one H200, 16 cores): h alone on pairs whose strays are
# their own, the GPU backends running them on the two cores (1f69da7,
# "after") against ba935de ("before", the whole search), alternated, two
# rounds, a process a run, rt-pipeline: 2M and 20M double points in a 5 cm
# cube beside one stray 2.5 km away against the same beside one 3.1 km
# away; the scale suite's cluster-100M (100M float points in a 2 mm cube
# beside 10 points 1-10 km away, each set its own; --verify).
BUNDLE=.devt  # (no validation layer carried: no tests in this call)
source tools/bench/device_prelude.sh
B=.devt/pp
python3 - <<'PY'
import numpy as np
at = np.array([512345.125, 5412345.5, 100.0])
def ply(path, p):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(p)}\nproperty double x\nproperty double y\nproperty double z\nend_header\n".encode())
        f.write(p.astype("<f8").tobytes())
for n, tag in ((2000000, "2m"), (20000000, "20m")):
    for name, seed, far in (("a", 1, 2500.0), ("b", 2, 3100.0)):
        r = np.random.default_rng(seed)
        p = at + r.random((n, 3)) * 0.05  # 5 cm cube
        ply(f"/tmp/{name}{tag}.ply", np.vstack([p, at + [far, -far, 0.5 * far]]))
PY
$B/rthdist-scale-gen cluster 100000000 31 /tmp/ca.ply > /dev/null && $B/rthdist-scale-gen cluster 100000000 32 /tmp/cb.ply > /dev/null
cat /tmp/ca.ply /tmp/cb.ply > /dev/null
run() {  # name, then the command
  local name=$1; shift
  timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
}
for r in 1 2; do
  for v in ba935 1f69d; do
    run stray2m-$v-$r $B/rthdist-$v /tmp/a2m.ply /tmp/b2m.ply --backend rt-pipeline --json --quiet
    run stray20m-$v-$r $B/rthdist-$v /tmp/a20m.ply /tmp/b20m.ply --backend rt-pipeline --json --quiet
    run cluster100m-$v-$r $B/rthdist-$v /tmp/ca.ply /tmp/cb.ply --backend rt-pipeline --verify --json --quiet
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
    c = j.get("counters", {})
    rows[name.rsplit("-", 1)[0]].append((t.get("total"), t.get("refine"), t.get("pieces"), j.get("hausdorff"), t.get("wall"),
        [c.get(k, {}).get("narrowed_targets") for k in ("a_to_b", "b_to_a")], (j.get("verify") or {}).get("ok")))
for k in sorted(rows):
    v = rows[k]
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v],
          "pieces", [round(x[2] or 0, 1) for x in v], "wall", [round(x[4] or 0) for x in v], "H", sorted({x[3] for x in v}), "narrowed", v[0][5], "verify", [x[6] for x in v])
PY
