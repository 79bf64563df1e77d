#!/usr/bin/env bash
# Session 25, call 6 (one H200, 16 cores): the tail's tree with its own copy
# of the corners in its order (a leaf's triangles from consecutive records;
# a descend-only call uploads its queries alone) against the build before
# (786cd6d), kept Engines of rt-pipeline, `rthdist-surface-bench --runs 9
# --warmup 2`, 3 rounds alternated; then the GPU surface tests on
# rt-pipeline with the validation layer.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx; M=$B/m; D=$B/data
python3 - <<'PY' || exit 1
import sys, numpy as np
sys.path.insert(0, "tools/bench")
from ply_points import read_ply, write_ply
v = read_ply(".devx/m/bun_zipper.ply").astype(np.float64)
rng = np.random.default_rng(1)
write_ply("/tmp/bunny10.ply", np.concatenate([v + rng.normal(0, 2e-4, v.shape) for _ in range(10)]).astype(np.float32))
PY
rows="$M/bun_zipper.ply:$M/bun_zipper_res3.ply $M/bun_zipper.ply:$M/bun_zipper_res4.ply /tmp/bunny10.ply:$M/bun_zipper_res3.ply /tmp/bunny10.ply:$M/bun_zipper_res4.ply $M/bun_zipper_res4.ply:$M/bun_zipper.ply $M/dragon_vrip_res4.ply.gz:$D/dragon_vrip.ply.gz $M/bun_zipper.ply:$M/bun_zipper_res2.ply"
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1))
    for v in before after; do
      timeout 120 $B/sb-$v ${row%%:*} ${row##*:} --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/s$i-$v-$r.json 2> $RES/s$i-$v-$r.err
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
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"])
            parts.append("%.3f [gpu %.3f tail %.3f upload %.3f]" % (k["total"], k["gpu"], k["gpu_tail"], k["upload"]))
        out += f"\n   {v} " + " / ".join(parts)
    print(out, "\n   H", sorted(hs))
PY
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 150 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
