#!/usr/bin/env bash
# Session 30, call 5 (one H200, 16 cores): the session's last build
# (sb-final: ranges of at most 8 triangles split in the middle, two leaves,
# and descent for up to 2^22 queries) against calls 2-4's (sb-new: the
# tree split at the Morton codes' highest differing bit down to leaves of
# at most 4, descent for up to 2^17 queries); kept rt-pipeline Engines,
# --runs 9 --warmup 2 --no-verify, all host threads, 3 rounds alternated,
# and in round 1 3 one-shot calls a process (a device each: the tree built
# in the call, tail_build). Carries the first part of Open3D's bundle
# (.o3d1) to /tmp/o3d for call 6 (s30f.sh).
BUNDLE=.devx
source tools/bench/device_prelude.sh
if [ -d .o3d1 ]; then mkdir -p /tmp/o3d && cp .o3d1/* /tmp/o3d/ && ls -la /tmp/o3d; fi
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
V="sb-new sb-final"
for f in $V; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 bunny-res2:bunny dragon-res4:dragon-res2 dragon-res2:dragon-res3 dragon-res2:dragon-res4 bunny-scans:bunny dragon-res2:dragon"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    one=""; [ $r = 1 ] && one="--one-shot 3"
    for v in $V; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify $one > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
  done
done
python3 - "$rows" "$V" <<'PY'
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
