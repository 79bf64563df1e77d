#!/usr/bin/env bash
# Session 23, call 4 (one H200, 16 cores): the exact pass's cost on double
# inputs with the level-at-a-time tree build (the session's last build)
# against the session's start (3ba5b4e), alternated, a process a run: the
# 2M strayed double clusters and the Dragon pair read as doubles.
source tools/bench/device_prelude.sh
B=.devs
D=$B/data
run() {
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 240 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
python3 - <<'PY'
import numpy as np
at = np.array([512345.125, 5412345.5, 100.0])
def ply(path, p):
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(p)}\nproperty double x\nproperty double y\nproperty double z\nend_header\n".encode())
        f.write(p.astype("<f8").tobytes())
for name, seed, far in (("ca", 1, 2500.0), ("cb", 2, 3100.0)):
    r = np.random.default_rng(seed)
    p = at + r.random((2000000, 3)) * 0.05
    ply(f"/tmp/{name}.ply", np.vstack([p, at + [far, -far, 0.5 * far]]))
PY
for r in 1 2 3; do
  for v in before after; do
    bin=$B/rthdist; [ $v = before ] && bin=$B/rthdist-before
    for be in cpu rt-pipeline; do
      run dragon-$be-$v-$r $bin $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz --per-point --backend $be --json --quiet
      run stray-$be-$v-$r $bin /tmp/ca.ply /tmp/cb.ply --per-point --backend $be --json --quiet
    done
  done
done
python3 - <<'PY'
import json, glob, os, collections
rows = collections.defaultdict(list)
for f in sorted(glob.glob("/tmp/res/*.json")):
    name = os.path.basename(f)[:-5]
    j = json.load(open(f)); t = j.get("timings_ms", {}); c = j.get("counters", {}) or {}
    mended = [(c.get(k) or {}).get("per_point_mended") for k in ("a_to_b", "b_to_a")]
    rows[name.rsplit("-", 1)[0]].append((t.get("total"), t.get("refine"), j.get("hausdorff"), mended, ((j.get("per_point") or {}).get("hd95") or {}).get("max")))
for k, v in sorted(rows.items()):
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v], "H", v[0][2], "mended", v[0][3], "hd95", v[0][4])
PY
