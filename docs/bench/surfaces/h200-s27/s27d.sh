#!/usr/bin/env bash
# Session 27, calls 4 and 5 (one H200, 16 cores): three builds' ways on the same
# rows, in one call, kept Engines of rt-pipeline, `rthdist-surface-bench
# --runs 9 --warmup 2`, 3 rounds alternated:
#   lanes  sb-before (0c39d63: lanes, descend-only up to 65,536 queries);
#   kept   sb-after (b79bf88: the GPU route's kept mesh and corners);
#   new    sb-new (709aa0c: the tail's count once a workgroup, the kept
#          mesh compared in chunks of 4,096 vertices).
# Then one traced call (RTHDIST_SUBMIT_TRACE=1) of bunny>res4 on sb-new.
# ROWS (call 5: the rows whose mesh is large, the host's part measured
# again: call 4's host was ~5x slower than call 3's throughout) and
# TESTS=0 (no test run) narrow it. The host's load is printed first.
cat /proc/loadavg
# Then the GPU surface tests on rt-pipeline with the validation layer.
# The bundle (.devx) carries the inputs of tools/bench/surface_inputs.py as
# m.tar.xz and the stripped binaries xz'ed (the carry's 64 MiB).
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B
for f in sb-before sb-after sb-new gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
M=$B/m
# row = points:mesh:the start's rule descended (1) or not (0)
rows=${ROWS:-"bunny:bunny-res3:1 bunny:bunny-res4:1 bunny-res4:bunny:1 bunny:bunny-res2:0 dragon-res4:dragon:0 armadillo:armadillo-dec:0 armadillo-dec:armadillo:0 bunny-scans:bunny:0 dragon:dragon-res2:0 dragon:dragon-res3:0 dragon:dragon-res4:0"}
bench() {  # binary points mesh out
  timeout 120 $B/$1 $M/$2.ply $M/$3.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $4.json 2> $4.err
}
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); IFS=: read -r a b old <<< "$row"
    bench sb-before $a $b $RES/s$i-lanes-$r
    bench sb-after $a $b $RES/s$i-kept-$r
    bench sb-new $a $b $RES/s$i-new-$r
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b, _ = row.split(":"); out, hs, med = f"{a} > {b}", set(), {}
    for v in ("lanes", "kept", "new"):
        parts, tot = [], []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; c = j["counters"]; hs.add(j["hausdorff"]); tot.append(k["total"])
            parts.append("%.3f [gpu %.3f pre %.3f frame %.3f up %.3f cert %.3f]" % (k["total"], k["gpu"], k["total"] - k["search"], k["frame"], k["upload"], k["certify"]))
        med[v] = statistics.median(tot) if tot else float("nan")
        out += f"\n   {v:5s} " + " / ".join(parts)
    print(out, "\n   medians: lanes %.3f kept %.3f new %.3f ms" % (med["lanes"], med["kept"], med["new"]), " H", sorted(hs))
PY
RTHDIST_SUBMIT_TRACE=1 timeout 60 $B/sb-new $M/bunny.ply $M/bunny-res4.ply --backend rt-pipeline --runs 3 --warmup 1 --no-verify > $RES/trace.json 2> $RES/trace.err; grep submit $RES/trace.err | tail -n 3
[ "${TESTS:-1}" = 0 ] && exit 0
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
