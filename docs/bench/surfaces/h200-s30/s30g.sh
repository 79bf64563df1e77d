#!/usr/bin/env bash
# Session 30, call 8 (one H200, 16 cores): Open3D 0.16.1 beside
# rthdist in the same run after the tail's tree split at the Morton codes'
# highest differing bit (sb-final: the session's last build, call 5's), on
# the issue's rows call 6 did not have: the armadillo and its decimation,
# the dragon's full mesh, and the Tang scenario (the bunny against its copy
# moved by 0.1 and 0.001 of the diagonal). Open3D's bundle
# (tools/bench/open3d_bundle.sh, 41 MB as tar.xz) travels in two parts:
# call 7 (PART=1) carries .o3d1 and copies it to /tmp/o3d; call 8, on the
# same warm machine, carries .o3d2 and .devl and runs the rows. Per row, 3
# rounds alternated: Open3D building its scene each run, Open3D with its
# scene built once (open3d-kept: each run its query alone), and
# rthdist-surface-bench on a kept Engine of rt-pipeline; 9 runs each
# (rthdist after 2 warm-up calls; Open3D's kept scene after one query).
# Medians, ms.
if [ "${PART:-2}" = 1 ]; then
  mkdir -p /tmp/o3d && cp .o3d1/* /tmp/o3d/ && ls -la /tmp/o3d; exit 0
fi
BUNDLE=.devl
source tools/bench/device_prelude.sh
[ -e /tmp/o3d/part1 ] || { echo "no /tmp/o3d/part1: the machine was not the warm one"; exit 3; }
cat /tmp/o3d/part1 .o3d2/part2 | tar xJ -C /tmp || exit 4
/tmp/open3d/run.sh -c "import open3d; print('open3d', open3d.__version__)" || exit 5
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devl/m.tar.xz -C $B
for f in sb-final; do xz -dc .devl/$f.xz > $B/$f; chmod +x $B/$f; done
M=$B/m
rows="armadillo:armadillo-dec armadillo-dec:armadillo dragon-res4:dragon dragon:dragon-res2 bunny:bunny-t0.1 bunny:bunny-t0.001"
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); a=${row%%:*}; b=${row##*:}
    timeout 120 /tmp/open3d/run.sh tools/bench/surface_peers.py --open3d-worker $M/$a.ply $M/$b.ply 9 > $RES/s$i-o3d-$r.json 2> $RES/s$i-o3d-$r.err
    timeout 120 /tmp/open3d/run.sh tools/bench/surface_peers.py --open3d-worker $M/$a.ply $M/$b.ply 9 --open3d-kept > $RES/s$i-o3dkept-$r.json 2> $RES/s$i-o3dkept-$r.err
    timeout 120 $B/sb-final $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/s$i-rth-$r.json 2> $RES/s$i-rth-$r.err
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
print("| row | Open3D (scene each run) | Open3D (scene kept) | rthdist kept rt-pipeline | Open3D / rthdist | Open3D kept / rthdist | H rthdist | H Open3D |")
print("|---|---:|---:|---:|---:|---:|---:|---:|")
for i, row in enumerate(sys.argv[1].split(), 1):
    med = {}
    h = {}
    for v in ("o3d", "o3dkept", "rth"):
        per = []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: continue
            if v.startswith("rth"): per.append(j["kept_median_ms"]["total"]); h[v] = j["hausdorff"]
            else: per.append(statistics.median(j["ms"])); h[v] = j["h"]
        med[v] = statistics.median(per) if per else float("nan")
    a, b = row.split(":")
    print(f"| {a}>{b} | %.3f | %.3f | %.3f | %.1fx | %.2fx | %.9g | %.9g |" % (med["o3d"], med["o3dkept"], med["rth"], med["o3d"] / med["rth"], med["o3dkept"] / med["rth"], h.get("rth", float("nan")), h.get("o3d", float("nan"))))
PY
