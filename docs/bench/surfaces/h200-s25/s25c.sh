#!/usr/bin/env bash
# Session 25, call 3 (one H200, 16 cores): the BLAS built with
# PREFER_FAST_BUILD (src/gpu/accel.cpp) against PREFER_FAST_TRACE (the
# build before: rthdist-bench-before, sb), alternated in one call:
#   1. docs/bench/gpu.md's rows (tools/bench/gpu_certificate_ab.sh, 2 rounds);
#   2. kept-Engine point-to-surface rows with rays (rthdist-surface-bench,
#      rt-pipeline, --runs 9 --warmup 2, 2 rounds), 1M and 10M samples of
#      dragon_vrip_res2's surface (seed 1) to res3 among them;
#   3. the GPU test suites on rt-pipeline with the validation layer.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx
M=$B/m
D=$B/data
bash tools/bench/gpu_certificate_ab.sh $B $RES/rows 2 > /dev/null 2>&1
cat $RES/rows/table.txt
python3 tools/bench/sample_surface.py $D/dragon_vrip_res2.ply.gz 1000000 1 /tmp/s1m.ply > /dev/null || exit 1
python3 tools/bench/sample_surface.py $D/dragon_vrip_res2.ply.gz 10000000 1 /tmp/s10m.ply > /dev/null || exit 1
rows="$M/bun_zipper.ply:$M/bun_zipper_res2.ply $D/dragon_vrip.ply.gz:$D/dragon_vrip_res2.ply.gz $D/dragon_vrip.ply.gz:$M/dragon_vrip_res3.ply.gz $D/dragon_vrip.ply.gz:$M/dragon_vrip_res4.ply.gz /tmp/s1m.ply:$M/dragon_vrip_res3.ply.gz /tmp/s10m.ply:$M/dragon_vrip_res3.ply.gz"
for r in 1 2; do
  i=0
  for row in $rows; do
    i=$((i + 1))
    for v in before after; do
      bin=$B/sb; [ $v = after ] && bin=$B/sb-after
      timeout 120 $bin ${row%%:*} ${row##*:} --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/s$i-$v-$r.json 2> $RES/s$i-$v-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, os
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b = row.split(":"); out, hs = f"{os.path.basename(a)} > {os.path.basename(b)}", set()
    for v in ("before", "after"):
        parts = []
        for r in (1, 2):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"])
            parts.append("%.3f [gpu %.3f build %.3f]" % (k["total"], k["gpu"], k["gpu_build"]))
        out += f" | {v} " + " / ".join(parts)
    print(out, "| H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_gpu_tests > $RES/gpu_tests.txt 2>&1; echo "gpu tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_tests.txt | tr '\n' ' ')"
timeout 150 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
grep -ci "validation" $RES/gpu_tests.txt $RES/gpu_surface_tests.txt
