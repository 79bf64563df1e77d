#!/usr/bin/env bash
# Session 27, call 1 (one H200, 16 cores): several lanes per query in the
# surface tail's descent (design.md §11 "Lanes of one query") against one
# lane (RTHDIST_SURFACE_TAIL_LANES=1: the shader's laneBits 0 path, the
# descent as it was), same binary, kept Engines of rt-pipeline,
# `rthdist-surface-bench --runs 9 --warmup 2`, 3 rounds alternated; a lane
# sweep on the descending rows; then the GPU surface tests on rt-pipeline
# with the validation layer. Inputs: tools/bench/surface_inputs.py (.devx/m).
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx; M=$B/m
rows="$M/bunny.ply:$M/bunny-res3.ply $M/bunny.ply:$M/bunny-res4.ply $M/bunny-res4.ply:$M/bunny.ply $M/bunny.ply:$M/bunny-res2.ply $M/dragon-res4.ply:$M/dragon.ply $M/armadillo.ply:$M/armadillo-dec.ply $M/armadillo-dec.ply:$M/armadillo.ply $M/bunny-scans.ply:$M/bunny.ply"
run() {  # lanes row out [extra env]
  local lanes=$1 row=$2 out=$3
  if [ "$lanes" = default ]; then unset RTHDIST_SURFACE_TAIL_LANES; else export RTHDIST_SURFACE_TAIL_LANES=$lanes; fi
  [ -e "${row%%:*}" ] && [ -e "${row##*:}" ] || return 0
  timeout 120 $B/rthdist-surface-bench ${row%%:*} ${row##*:} --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $out.json 2> $out.err
  unset RTHDIST_SURFACE_TAIL_LANES
}
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1))
    run 1 $row $RES/s$i-one-$r
    run default $row $RES/s$i-lanes-$r
    RTHDIST_SURFACE_DESCEND=1 run 1 $row $RES/s$i-done-$r
    RTHDIST_SURFACE_DESCEND=1 run default $row $RES/s$i-dlanes-$r
  done
done
python3 - "$rows" <<'PY'
import json, sys, os
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b = row.split(":"); out, hs = f"{os.path.basename(a)} > {os.path.basename(b)}", set()
    for v in ("one", "lanes", "done", "dlanes"):
        parts = []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; hs.add(j["hausdorff"])
            parts.append("%.3f [gpu %.3f tail %.3f lanes %s]" % (k["total"], k["gpu"], k["gpu_tail"], j.get("counters", {}).get("tail_lanes", j.get("tail_lanes", "?"))))
        out += f"\n   {v:6s} " + " / ".join(parts)
    print(out, "\n   H", sorted(hs))
PY
for row in "$M/bunny-res4.ply:$M/bunny.ply" "$M/dragon-res4.ply:$M/dragon.ply" "$M/armadillo-dec.ply:$M/armadillo.ply"; do
  for l in 1 2 4 8 16 32; do
    RTHDIST_SURFACE_DESCEND=1 run $l $row $RES/sweep-$(basename ${row%%:*})-$l
    python3 -c "import json,sys; j=json.load(open(sys.argv[1])); k=j['kept_median_ms']; print(sys.argv[2], sys.argv[3], 'total %.3f gpu %.3f tail %.3f' % (k['total'], k['gpu'], k['gpu_tail']))" $RES/sweep-$(basename ${row%%:*})-$l.json $(basename ${row%%:*}) $l 2>&1 | tail -1
  done
done
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
