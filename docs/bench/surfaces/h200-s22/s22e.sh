#!/usr/bin/env bash
# Session 22, call 5 (one H200, 16 cores; build 6283818): per-point
# distances on kept Engines with and without Engine::recycle
# (rthdist-surface-bench --per-point [--recycle], 10M samples of the
# Dragon's surface to dragon_vrip_res2's triangles, medians of 5, the
# recycled calls alternated with fresh ones), then the surface GPU tests
# with the validation layer on this build (the recycled-arrays test among them).
source tools/bench/device_prelude.sh
B=.devs
M=$B/data/dragon-res2.ply
python3 tools/bench/sample_surface.py $B/data/dragon_vrip.ply.gz 10000000 1 /tmp/d10m.ply || exit 1
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 150 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for r in 1 2; do
  for b in rt-pipeline cpu; do
    for m in fresh recycle; do
      flag=""; [ $m = recycle ] && flag=--recycle
      run kept-$b-$m-$r $B/rthdist-surface-bench /tmp/d10m.ply $M --backend $b --per-point --runs 5 --warmup 1 --no-verify $flag
      run dist-$b-$m-$r $B/rthdist-surface-bench /tmp/d10m.ply $M --backend $b --per-point --distances-only --runs 5 --warmup 1 --no-verify $flag
    done
  done
done
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_gpu_surface_tests > $RES/surface_tests.txt 2>&1; echo "surface tests exit $?"
grep -E "^\[  (PASSED|FAILED) |tests ran|entries not|recomputed on" $RES/surface_tests.txt | tail -6
python3 - <<'PY'
import json, glob, os
for f in sorted(glob.glob("/tmp/res/*-[12].json")):
    j = json.load(open(f)); m = j["kept_median_ms"]
    print(os.path.basename(f), "total %.1f certify %.1f per_point %.1f" % (m["total"], m.get("certify", 0), m.get("per_point", 0)), "all", [round(x) for x in j["kept_total_ms_all"]])
PY
