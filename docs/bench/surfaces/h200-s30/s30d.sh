#!/usr/bin/env bash
# Session 30, call 4 (one H200, 16 cores): the session's last build (sb-fin:
# the tree of call 2 and descent for up to 2^22 queries, whatever the
# triangles) against calls 2-3's (sb-new: descent for up to 2^17 queries), on
# the rows whose route the rule changed (bunny-scans>bunny 362,272
# queries, dragon>dragon-res2 437,645, pts4m>dragon-res2 4M: radii ->
# descent) and two it did not; kept rt-pipeline Engines, --runs 9
# --warmup 2 --no-verify, 3 rounds alternated; then the GPU surface tests
# on rt-pipeline with the validation layer (gst, sb-fin's code).
BUNDLE=.devf
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devf/m.tar.xz -C $B; M=$B/m
V="sb-new sb-fin"
for f in $V gst; do xz -dc .devf/$f.xz > $B/$f; chmod +x $B/$f; done
export VK_LAYER_PATH=$PWD/.devf/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 300 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
unset VK_LAYER_PATH RTHDIST_TEST_BACKEND
python3 - $M <<'PY'
import sys, numpy as np
M = sys.argv[1]
def read(p):
    f = open(p, "rb"); nv = nf = 0
    while True:
        l = f.readline().decode().strip()
        if l.startswith("element vertex"): nv = int(l.split()[2])
        if l.startswith("element face"): nf = int(l.split()[2])
        if l == "end_header": break
    v = np.frombuffer(f.read(12 * nv), dtype="<f4").reshape(nv, 3)
    faces = np.frombuffer(f.read(13 * nf), dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]))["i"]
    return v.astype(np.float64), faces
v, f = read(f"{M}/dragon-res2.ply")
a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
rng = np.random.default_rng(7); n = 4_000_000
t = rng.choice(len(f), n, p=area / area.sum())
r1, r2 = rng.random(n), rng.random(n); s = np.sqrt(r1)
p = (1 - s)[:, None] * a[t] + (s * (1 - r2))[:, None] * b[t] + (s * r2)[:, None] * c[t] + rng.normal(0, 1e-4, (n, 3))
with open(f"{M}/pts4m.ply", "wb") as o:
    o.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n".encode())
    o.write(p.astype("<f4").tobytes())
PY
rows="bunny-scans:bunny dragon:dragon-res2 pts4m:dragon-res2 bunny:bunny-res4 dragon-res2:dragon-res3"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    for v in $V; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
  done
done
python3 - "$rows" "$V" <<'PY'
import json, sys, statistics, os
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); line = f"{a}>{b}:"; hs = set()
    for v in sys.argv[2].split():
        tot, parts = [], []
        for r in (1, 2, 3):
            f = f"{R}/g-{a}-{b}-{v}-{r}.json"
            if not os.path.exists(f): continue
            try: j = json.load(open(f))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"]); hs.add(j["hausdorff"])
            parts.append((k["upload"], k["device"], k["gpu"], k["readback"], k["certify"], j["counters"]["radii"], j["counters"]["tail_lanes"]))
        if not tot: continue
        med = lambda i: statistics.median(p[i] for p in parts)
        line += f"\n   {v:8s} " + " ".join("%.3f" % x for x in tot) + "  median %.3f (upload %.3f device %.3f gpu %.3f readback %.3f certify %.3f radii %d lanes %d)" % (statistics.median(tot), med(0), med(1), med(2), med(3), med(4), parts[0][5], parts[0][6])
    print(line, "\n   H", sorted(hs))
PY
