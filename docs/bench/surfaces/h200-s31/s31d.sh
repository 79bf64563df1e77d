#!/usr/bin/env bash
# Session 31, call 5 (one H200, 16 cores): the CPU backend's triangle BVH
# build against its thread count (the CLI, --backend cpu --threads T, one
# process a run, 7 runs each): whether a small mesh's build is slower on 16
# threads than on a few.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; tar xJf .dev31/m.tar.xz -C $B; M=$B/m
xz -dc .dev31/rth-new.xz > $B/rthdist; chmod +x $B/rthdist
for row in bunny-res4:bunny bunny:bunny-res3 dragon-res4:dragon-res2 dragon-res4:dragon bunny:bunny-res2; do a=${row%%:*}; b=${row##*:}
  for t in 1 2 4 8 16; do
    for k in 1 2 3 4 5 6 7; do $B/rthdist $M/$a.ply $M/$b.ply --surface b --backend cpu --threads $t --json > $RES/t-$a-$b-$t-$k.json 2>/dev/null; done
  done
done
python3 - <<'PY'
import json, glob, statistics
rows = sorted({f.split('/t-')[1].rsplit('-', 2)[0] for f in glob.glob('/tmp/res/t-*.json')})
for r in rows:
    line = r + ":"
    for t in (1, 2, 4, 8, 16):
        js = [json.load(open(f)) for f in glob.glob(f'/tmp/res/t-{r}-{t}-*.json')]
        b = statistics.median(j['timings_ms']['build'] for j in js); s = statistics.median(j['timings_ms']['search'] for j in js); tt = statistics.median(j['timings_ms']['total'] for j in js)
        line += f"  t{t}: build {b:.2f} search {s:.2f} total {tt:.2f} |"
    print(line)
PY
