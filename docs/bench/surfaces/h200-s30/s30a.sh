#!/usr/bin/env bash
# Session 30, call 1 (one H200, 16 cores): the tail's tree split top down
# at the Morton codes' highest differing bit (sb-lbvh, leaves of at most 4)
# against the tree of 434e634 (sb-pair: levels paired bottom up over the
# sorted order), and the same split with leaves of at most 8 (sb-lbvh8, an
# experiment); kept rt-pipeline Engines, --runs 9 --warmup 2 --no-verify,
# all host threads, 3 rounds alternated; one-shot calls (a device each,
# the tree built in the call: tail_build) in round 1; bunny-scans>bunny
# (362,272 queries, radii by the rule) descending every query
# (RTHDIST_SURFACE_DESCEND=1) against the rule; then the GPU surface tests
# on rt-pipeline with the validation layer (gst, sb-lbvh's code).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
V="sb-pair sb-lbvh sb-lbvh8"
for f in $V gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 bunny-res2:bunny dragon-res4:dragon-res2 dragon-res2:dragon-res3 dragon-res2:dragon-res4 bunny-scans:bunny"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    one=""; [ $r = 1 ] && one="--one-shot 3"
    for v in $V; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify $one > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
    if [ $a = bunny-scans ]; then
      RTHDIST_SURFACE_DESCEND=1 timeout 60 $B/sb-lbvh $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/g-$a-$b-sb-lbvh-desc-$r.json 2> $RES/g-$a-$b-sb-lbvh-desc-$r.err
    fi
  done
done
python3 - "$rows" "$V sb-lbvh-desc" <<'PY'
import json, sys, statistics, os
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); line = f"{a}>{b}:"; hs = set()
    for v in sys.argv[2].split():
        tot, parts, one = [], [], None
        for r in (1, 2, 3):
            f = f"{R}/g-{a}-{b}-{v}-{r}.json"
            if not os.path.exists(f): continue
            try: j = json.load(open(f))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"]); hs.add(j["hausdorff"])
            parts.append((k["upload"], k["device"], k["gpu"], k["readback"], k["certify"], j["counters"]["radii"], j["counters"]["tail_lanes"]))
            if "one_shot_median_ms" in j: one = j["one_shot_median_ms"]
        if not tot: continue
        med = lambda i: statistics.median(p[i] for p in parts)
        line += f"\n   {v:13s} " + " ".join("%.3f" % x for x in tot) + "  median %.3f (upload %.3f device %.3f gpu %.3f readback %.3f certify %.3f radii %d lanes %d)" % (statistics.median(tot), med(0), med(1), med(2), med(3), med(4), parts[0][5], parts[0][6])
        if one: line += "  one-shot total %.3f tail_build %.3f gpu %.3f" % (one["total"], one["tail_build"], one["gpu"])
    print(line, "\n   H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
