#!/usr/bin/env bash
# Session 31, call 3 (one H200, 16 cores, rt-pipeline): the GPU surface
# route on a kept Engine, session 30's last build (sb-final) against this
# session's (sb-new: the tail tree's subtrees on the caller's threads; the
# CPU tree the GPU route's proof measures with, from a mesh's second call,
# now built over the Morton order), --runs 9 --warmup 2 --no-verify, all
# host threads, 3 rounds alternated, medians: the rows nearest session 30's
# 10x against Open3D and the rows with most proof work.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .dev31/m.tar.xz -C $B; M=$B/m
V="sb-final sb-new"
for f in $V; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res4 bunny:bunny-res3 bunny:bunny-res2 bunny-res4:bunny bunny-res2:bunny dragon-res4:dragon-res2 dragon-res2:dragon-res3 bunny-scans:bunny dragon-res4:dragon dragon:dragon-res2"
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
        tot = []
        for r in (1, 2, 3):
            f = f"{R}/g-{a}-{b}-{v}-{r}.json"
            try: j = json.load(open(f))
            except Exception: continue
            tot.append(j["kept_median_ms"]["total"]); hs.add(j["hausdorff"])
        if tot: line += f"\n   {v:9s} " + " ".join("%.3f" % x for x in tot) + "  median %.3f" % statistics.median(tot)
    print(line, "\n   H", sorted(hs))
PY
