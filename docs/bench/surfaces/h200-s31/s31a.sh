#!/usr/bin/env bash
# Session 31, call 1 (one H200, 16 cores, rt-pipeline):
# 1. The surface-to-surface GPU tests (tests/api/surface_pair_gpu_test.cpp:
#    surface_pair_gpu, whose sample batches the tail's tree searches) under
#    the validation layer, on this session's build.
# 2. The tail tree's task passes on the caller's threads (sb-thr) against
#    session 30's last build (sb-final: the task passes capped at
#    triangles / 2^15 + 1 workers): one-shot calls (a device each, the tree
#    built in the call: tail_build) and kept Engines, 3 rounds alternated,
#    on meshes below 491,520 triangles (where the cap binds on 16 cores).
# 3. The point-to-surface GPU tests under the validation layer.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .dev31/m.tar.xz -C $B; M=$B/m
for f in sb-final sb-thr spg gst; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
export VK_LAYER_PATH=$PWD/.dev31/layers
( export RTHDIST_TEST_BACKEND=rt-pipeline
  timeout 240 $B/spg > $RES/surface_pair_gpu_tests.txt 2>&1
  echo "surface pair tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/surface_pair_gpu_tests.txt | tr '\n' ' ')" )
V="sb-final sb-thr"
rows="bunny-scans:bunny dragon:dragon-res2 bunny-res4:bunny dragon-res4:dragon-res2 bunny:bunny-res3 armadillo-dec:armadillo"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    for v in $V; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 5 --warmup 2 --no-verify --one-shot 5 > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
  done
done
python3 - "$rows" "$V" <<'PY'
import json, sys, statistics, os
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); line = f"{a}>{b}:"; hs = set()
    for v in sys.argv[2].split():
        kept, ones, builds = [], [], []
        for r in (1, 2, 3):
            f = f"{R}/g-{a}-{b}-{v}-{r}.json"
            if not os.path.exists(f): continue
            try: j = json.load(open(f))
            except Exception: continue
            kept.append(j["kept_median_ms"]["total"]); hs.add(j["hausdorff"])
            o = j.get("one_shot_median_ms")
            if o: ones.append(o["total"]); builds.append(o["tail_build"])
        if not kept: continue
        line += f"\n   {v:9s} kept " + " ".join("%.3f" % x for x in kept) + " (median %.3f)" % statistics.median(kept)
        if ones: line += "  one-shot total " + " ".join("%.2f" % x for x in ones) + " (median %.2f)  tail_build " % statistics.median(ones) + " ".join("%.2f" % x for x in builds) + " (median %.2f)" % statistics.median(builds)
    print(line, "\n   H", sorted(hs))
PY
( export RTHDIST_TEST_BACKEND=rt-pipeline
  timeout 200 $B/gst > $RES/gpu_surface_tests.txt 2>&1
  echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')" )
