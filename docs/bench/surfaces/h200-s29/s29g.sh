#!/usr/bin/env bash
# Session 29, call 8 (one H200, 16 cores): the worker pool kept polling
# while a GPU submission is waited for (core::keepPoolWarmUntil, from
# gpu::Context::submitAndWait: the pass after the wait finds the workers
# awake), and descent for up to 131,072 queries (was 65,536): sb-warm against
# 90b6f7c (sb-fq), kept rt-pipeline Engines, --runs 9 --warmup 2
# --no-verify, all host threads, 3 rounds alternated; then the GPU surface
# tests on rt-pipeline with the validation layer (gst, sb-warm's code).
# The polling during the wait changed nothing measurable and was not kept;
# the descent's reach was (surface_search.hpp, kDescendQueries).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
for f in sb-fq sb-warm gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 bunny-res2:bunny dragon-res4:dragon-res2 dragon-res2:dragon-res3 dragon-res2:dragon-res4"
for r in 1 2 3; do
  for row in $rows; do a=${row%%:*}; b=${row##*:}
    for v in sb-fq sb-warm; do
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); line = f"{a}>{b}:"; hs = set()
    for v in ("sb-fq", "sb-warm"):
        tot, parts = [], []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/g-{a}-{b}-{v}-{r}.json"))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"]); hs.add(j["hausdorff"])
            parts.append((k["upload"], k["device"], k["gpu"], k["readback"], k["certify"], j["counters"]["radii"]))
        med = lambda i: statistics.median(p[i] for p in parts)
        line += f"\n   {v:8s} " + " ".join("%.3f" % x for x in tot) + "  median %.3f (upload %.3f device %.3f gpu %.3f readback %.3f certify %.3f radii %d)" % (statistics.median(tot), med(0), med(1), med(2), med(3), med(4), parts[0][5])
    print(line, "\n   H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
