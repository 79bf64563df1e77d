#!/usr/bin/env bash
# Session 30, call 2 (one H200, 16 cores): the tail's tree split top down
# at the Morton codes' highest differing bit, laid out as committed (sb-dfs:
# ranges of more than 8,192 triangles split a level at a time, each smaller
# one's subtree depth first on the worker pool; call 1's sb-lbvh was laid
# out a level at a time), against 434e634's tree (sb-pair: levels
# paired bottom up over the sorted order); kept rt-pipeline Engines, --runs
# 9 --warmup 2 --no-verify, all host threads, 3 rounds alternated, and in
# round 1 3 one-shot calls a process (a device each: the tree built in the
# call, tail_build). Rows past the descent's rule (up to 131,072 queries) also
# descending every query (RTHDIST_SURFACE_DESCEND=1, sb-dfs), rows within
# it also on the radii (=0): bunny-scans>bunny (362,272 queries),
# dragon>dragon-res2 (437,645), pts4m>dragon-res2 (4M points sampled on
# dragon_vrip_res2's triangles by area, Gaussian noise 1e-4, seed 7),
# bunny>bunny-t0.1 and dragon-res2>dragon. Then the GPU surface tests on
# rt-pipeline with the validation layer where the bundle has them (gst,
# sb-dfs's code; in this call they ran in call 3, s30c.sh, which has the
# same code). Carries the first part of Open3D's bundle (.o3d1) to /tmp/o3d
# for call 3.
BUNDLE=.devx
source tools/bench/device_prelude.sh
if [ -d .o3d1 ]; then mkdir -p /tmp/o3d && cp .o3d1/* /tmp/o3d/ && ls -la /tmp/o3d; fi
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
V="sb-pair sb-dfs"
for f in $V; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
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
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 bunny-res2:bunny dragon-res4:dragon-res2 dragon-res2:dragon-res3 dragon-res2:dragon-res4 bunny-scans:bunny dragon:dragon-res2 pts4m:dragon-res2 bunny:bunny-t0.1 dragon-res2:dragon"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    one=""; [ $r = 1 ] && one="--one-shot 3"
    for v in $V; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify $one > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
    case $row in
      bunny-scans:*|dragon:*|pts4m:*) d=1 ;;
      bunny:bunny-t0.1|dragon-res2:dragon) d=0 ;;
      *) d= ;;
    esac
    if [ -n "$d" ]; then
      RTHDIST_SURFACE_DESCEND=$d timeout 60 $B/sb-dfs $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/g-$a-$b-sb-dfs-d$d-$r.json 2> $RES/g-$a-$b-sb-dfs-d$d-$r.err
    fi
  done
done
python3 - "$rows" "$V sb-dfs-d1 sb-dfs-d0" <<'PY'
import json, sys, statistics, os
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); line = f"{a}>{b}:"; hs = set()
    for v in sys.argv[2].split():
        tot, parts, ones = [], [], []
        for r in (1, 2, 3):
            f = f"{R}/g-{a}-{b}-{v}-{r}.json"
            if not os.path.exists(f): continue
            try: j = json.load(open(f))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"]); hs.add(j["hausdorff"])
            parts.append((k["upload"], k["device"], k["gpu"], k["readback"], k["certify"], j["counters"]["radii"], j["counters"]["tail_lanes"]))
            if "one_shot_median_ms" in j: ones.append(j["one_shot_median_ms"])
        if not tot: continue
        med = lambda i: statistics.median(p[i] for p in parts)
        line += f"\n   {v:10s} " + " ".join("%.3f" % x for x in tot) + "  median %.3f (upload %.3f device %.3f gpu %.3f readback %.3f certify %.3f radii %d lanes %d)" % (statistics.median(tot), med(0), med(1), med(2), med(3), med(4), parts[0][5], parts[0][6])
        if ones: line += "  one-shot tail_build %s total %.1f" % ("/".join("%.2f" % o["tail_build"] for o in ones), statistics.median(o["total"] for o in ones))
    print(line, "\n   H", sorted(hs))
PY
[ -e .devx/gst.xz ] || exit 0
xz -dc .devx/gst.xz > $B/gst; chmod +x $B/gst
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
