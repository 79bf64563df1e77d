#!/usr/bin/env bash
# Session 25, call 1 (one H200, 16 cores): does the GPU point-to-surface
# search depend on the queries' order? The same query sets written in their
# file's order, in Morton order (10 bits an axis over their box) and in a
# random order (.devx/reorder.py), against the bunny's and the Dragon's
# decimations and 1M samples of the Dragon's res2 surface (sample_surface.py,
# seed 1; its order is the sampler's) to res3: kept Engines of rt-pipeline
# and cpu, `rthdist-surface-bench --runs 9 --warmup 2`, two rounds.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx
M=$B/m
python3 tools/bench/sample_surface.py $M/dragon_vrip_res2.ply.gz 1000000 1 /tmp/s1m.ply > /dev/null || exit 1
python3 $B/reorder.py $M/bun_zipper.ply /tmp/bunny || exit 1
python3 $B/reorder.py $M/dragon_vrip.ply.gz /tmp/dragon || exit 1
python3 $B/reorder.py /tmp/s1m.ply /tmp/s1m || exit 1
rows=""
for o in orig morton random; do
  for t in bun_zipper_res2.ply bun_zipper_res3.ply bun_zipper_res4.ply; do rows="$rows /tmp/bunny-$o.ply:$M/$t"; done
  for t in dragon_vrip_res2.ply.gz dragon_vrip_res3.ply.gz dragon_vrip_res4.ply.gz; do rows="$rows /tmp/dragon-$o.ply:$M/$t"; done
  rows="$rows /tmp/s1m-$o.ply:$M/dragon_vrip_res3.ply.gz"
done
for r in 1 2; do
  i=0
  for row in $rows; do
    i=$((i + 1)); a=${row%%:*}; b=${row##*:}
    for be in rt-pipeline cpu; do
      timeout 120 $B/sb $a $b --backend $be --runs 9 --warmup 2 --no-verify \
        > $RES/$i-$be-$r.json 2> $RES/$i-$be-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, os
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b = row.split(":")
    out = f"{os.path.basename(a)} > {os.path.basename(b)}"
    hs = set()
    for be in ("rt-pipeline", "cpu"):
        parts = []
        for r in (1, 2):
            try:
                j = json.load(open(f"{R}/{i}-{be}-{r}.json"))
            except Exception:
                parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"])
            parts.append("%.3f (gpu %.3f tail %.3f build %.3f)" % (k["total"], k["gpu"], k["gpu_tail"], k["gpu_build"]) if be != "cpu" else "%.3f" % k["total"])
        out += f" | {be} " + " / ".join(parts)
    print(out, "| H", sorted(hs))
PY
