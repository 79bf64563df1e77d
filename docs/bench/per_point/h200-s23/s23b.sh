#!/usr/bin/env bash
# Session 23, call 3 (one H200, 16 cores): the shipped build (the exact pass
# on double inputs only) against the session's start (3ba5b4e), alternated,
# a process a run: the float32 shells (no pass: level) and the Dragon pair
# read as doubles (the pass); then the engine's per-point, out-of-core and
# several-lanes tests and the GPU surface tests with the validation layer.
source tools/bench/device_prelude.sh
B=.devs
D=$B/data
run() {
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 240 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
$B/rthdist-scale-gen shell 10000000 61 /tmp/sa.ply > /dev/null && $B/rthdist-scale-gen shell 10000000 62 /tmp/sb.ply > /dev/null
for r in 1 2; do
  for v in before after; do
    bin=$B/rthdist; [ $v = before ] && bin=$B/rthdist-before
    for be in cpu rt-pipeline; do
      run dragon-$be-$v-$r $bin $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz --per-point --backend $be --json --quiet
      run shell-$be-$v-$r $bin /tmp/sa.ply /tmp/sb.ply --per-point --backend $be --json --quiet
    done
  done
done
python3 - <<'PY'
import json, glob, os, collections
rows = collections.defaultdict(list)
for f in sorted(glob.glob("/tmp/res/*.json")):
    name = os.path.basename(f)[:-5]
    j = json.load(open(f)); t = j.get("timings_ms", {}); c = j.get("counters", {}) or {}
    mended = [(c.get(k) or {}).get("per_point_mended") for k in ("a_to_b", "b_to_a")]
    rows[name.rsplit("-", 1)[0]].append((t.get("total"), t.get("refine"), j.get("hausdorff"), mended, ((j.get("per_point") or {}).get("hd95") or {}).get("max")))
for k, v in sorted(rows.items()):
    print(k, "total", [round(x[0] or 0, 1) for x in v], "refine", [round(x[1] or 0, 1) for x in v], "H", v[0][2], "mended", v[0][3], "hd95", v[0][4])
PY
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_engine_tests --gtest_filter='ExactPerPoint.*:NarrowedTargets.*:CallOptions.*:OutOfCore.*:SeveralDevices.*:PreparedSet.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E 'PASSED|FAILED|SKIPPED' $RES/engine_tests.txt | tail -3 | tr '\n' ' ')"
timeout 150 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "gpu surface tests exit $? $(grep -E 'PASSED|FAILED' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
