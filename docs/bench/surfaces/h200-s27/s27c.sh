#!/usr/bin/env bash
# Session 27, call 3 (one H200, 16 cores): three builds' ways on the same
# rows, in one call, kept Engines of rt-pipeline, `rthdist-surface-bench
# --runs 9 --warmup 2`, 3 rounds alternated:
#   start  the session's start (488a3a3) as sb-before runs it: one lane
#          (RTHDIST_SURFACE_TAIL_LANES=1) and the radii forced
#          (RTHDIST_SURFACE_DESCEND=0) where that rule took them;
#   lanes  sb-before (0c39d63: lanes, descend-only up to 65,536 queries);
#   kept   sb-after (b79bf88: the GPU route's kept mesh and corners).
# Then the GPU surface tests on rt-pipeline with the validation layer.
# The bundle (.devx) carries the inputs of tools/bench/surface_inputs.py as
# m.tar.xz and the stripped binaries xz'ed (the carry's 64 MiB).
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B
for f in sb-before sb-after gst rth; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
M=$B/m
# row = points:mesh:the start's rule descended (1) or not (0)
rows="bunny:bunny-res3:1 bunny:bunny-res4:1 bunny-res4:bunny:1 bunny:bunny-res2:0 dragon-res4:dragon:0 armadillo:armadillo-dec:0 armadillo-dec:armadillo:0 bunny-scans:bunny:0 dragon:dragon-res2:0 dragon:dragon-res3:0 dragon:dragon-res4:0"
bench() {  # binary points mesh out
  timeout 120 $B/$1 $M/$2.ply $M/$3.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $4.json 2> $4.err
}
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); IFS=: read -r a b old <<< "$row"
    if [ "$old" = 1 ]; then RTHDIST_SURFACE_TAIL_LANES=1 bench sb-before $a $b $RES/s$i-start-$r
    else RTHDIST_SURFACE_TAIL_LANES=1 RTHDIST_SURFACE_DESCEND=0 bench sb-before $a $b $RES/s$i-start-$r; fi
    bench sb-before $a $b $RES/s$i-lanes-$r
    bench sb-after $a $b $RES/s$i-kept-$r
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b, _ = row.split(":"); out, hs, med = f"{a} > {b}", set(), {}
    for v in ("start", "lanes", "kept"):
        parts, tot = [], []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; c = j["counters"]; hs.add(j["hausdorff"]); tot.append(k["total"])
            parts.append("%.3f [gpu %.3f pre %.3f frame %.3f up %.3f cert %.3f]" % (k["total"], k["gpu"], k["total"] - k["search"], k["frame"], k["upload"], k["certify"]))
        med[v] = statistics.median(tot) if tot else float("nan")
        out += f"\n   {v:5s} " + " / ".join(parts)
    print(out, "\n   medians: start %.3f lanes %.3f kept %.3f ms" % (med["start"], med["lanes"], med["kept"]), " H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
