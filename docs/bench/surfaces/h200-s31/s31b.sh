#!/usr/bin/env bash
# Session 31, call 2 (one H200, 16 cores):
# 1. The surface-to-surface and point-to-surface GPU tests under the
#    validation layer on rt-pipeline, on the session's last build (the CPU
#    tree the GPU routes' proofs measure with is now built over the Morton
#    order).
# 2. The CPU backend (the CLI, --backend cpu, every host thread, one process
#    a run) of the session's start (rth-old: 13777e4's CPU code) against
#    its last build (rth-new: queries start where the previous one ended;
#    the triangle BVH over the Morton order): points to surface and surface
#    to surface, 3 rounds alternated of 5 processes each, medians.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .dev31/m.tar.xz -C $B; M=$B/m
for f in rth-old rth-new spg gst; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
export VK_LAYER_PATH=$PWD/.dev31/layers
for t in spg gst; do
  ( export RTHDIST_TEST_BACKEND=rt-pipeline
    timeout 200 $B/$t > $RES/$t-tests.txt 2>&1
    echo "$t exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/$t-tests.txt | tr '\n' ' ')" )
done
rows="bunny:bunny-res2:b bunny:bunny-res3:b bunny:bunny-res4:b bunny-res4:bunny:b dragon:dragon-res2:b dragon-res4:dragon:b bunny-scans:bunny:b bunny:bunny-t0.1:b bunny:bunny-res2:both dragon-res2:dragon-res3:both dragon:dragon-res2:both"
for r in 1 2 3; do
  for row in $rows; do IFS=: read a b s <<< "$row"
    for v in rth-old rth-new; do
      for k in 1 2 3 4 5; do
        timeout 60 $B/$v $M/$a.ply $M/$b.ply --surface $s --backend cpu --json > $RES/c-$a-$b-$s-$v-$r-$k.json 2> /dev/null
      done
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics, glob
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b, s = row.split(":"); line = f"{a}>{b} --surface {s}:"
    for v in ("rth-old", "rth-new"):
        tot, build, search, vals = [], [], [], set()
        for f in sorted(glob.glob(f"{R}/c-{a}-{b}-{s}-{v}-*.json")):
            try: j = json.load(open(f))
            except Exception: continue
            t = j["timings_ms"]; tot.append(t["total"]); build.append(t["build"]); search.append(t["search"])
            vals.add(str(j.get("bounds") or j.get("hausdorff")))
        if tot:
            line += f"\n   {v}: total median %.2f ms (build %.2f, search %.2f; %d runs)  value %s" % (statistics.median(tot), statistics.median(build), statistics.median(search), len(tot), sorted(vals))
    print(line)
PY
