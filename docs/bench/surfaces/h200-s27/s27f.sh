#!/usr/bin/env bash
# Session 27, call 8 (one H200, 16 cores): the GPU route's kept BVH for the
# proof (9fd64df, sb-tree) against 709aa0c (sb-new), kept Engines of
# rt-pipeline, `rthdist-surface-bench --runs 9 --warmup 2` (the BVH is
# built in the warm-up's second call), 3 rounds alternated, on the rows of
# the session's table; then the GPU surface tests on rt-pipeline with the
# validation layer (9fd64df).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B
for f in sb-new sb-tree gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
M=$B/m
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 dragon-res4:dragon armadillo:armadillo-dec armadillo-dec:armadillo bunny-scans:bunny dragon:dragon-res2 dragon:dragon-res3 dragon:dragon-res4"
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); a=${row%%:*}; b=${row##*:}
    for v in sb-new sb-tree; do
      timeout 120 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/s$i-$v-$r.json 2> $RES/s$i-$v-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b = row.split(":"); out, hs, med = f"{a} > {b}", set(), {}
    for v in ("sb-new", "sb-tree"):
        parts, tot = [], []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"]); tot.append(k["total"])
            parts.append("%.3f [gpu %.3f cert %.3f]" % (k["total"], k["gpu"], k["certify"]))
        med[v] = statistics.median(tot) if tot else float("nan")
        out += f"\n   {v:7s} " + " / ".join(parts)
    print(out, "\n   medians: 709aa0c %.3f 9fd64df %.3f ms" % (med["sb-new"], med["sb-tree"]), " H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
