#!/usr/bin/env bash
# Session 24, call 1 (one H200, 16 cores): the auto Engine's surface route
# (api::autoSurfaceOnGpu, a84deff): kept Engines of auto, cpu and
# rt-pipeline on the points rows whose meshes were carried, and 1M / 10M
# samples of dragon_vrip_res2's surface to dragon res3, alternated, two
# rounds of `rthdist-surface-bench --runs 9 --warmup 2` (kept Engine,
# medians); then the engine tests an auto Engine on a lent device touches,
# with the validation layer (DeviceInput: the device set up for kAuto is
# the rt-pipeline's on a device without ray queries).
BUNDLE=.devt
source tools/bench/device_prelude.sh
B=.devt
M=$B/m
python3 tools/bench/sample_surface.py $M/dragon_vrip_res2.ply.gz 1000000 1 /tmp/s1m.ply > /dev/null || exit 1
python3 tools/bench/sample_surface.py $M/dragon_vrip_res2.ply.gz 10000000 1 /tmp/s10m.ply > /dev/null || exit 1
rows="bunny:bunny-res2 bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny dragon:dragon-res2 dragon:dragon-res3 dragon:dragon-res4 dragon-res4:dragon s1m:dragon-res3 s10m:dragon-res3"
path() { case $1 in s1m|s10m) echo /tmp/$1.ply ;; *) echo $M/$1.ply.gz ;; esac; }
for r in 1 2; do
  for row in $rows; do
    a=${row%%:*}; b=${row##*:}
    for be in auto cpu rt-pipeline; do
      timeout 120 $B/sb $(path $a) $(path $b) --backend $be --runs 9 --warmup 2 --no-verify \
        > $RES/$a-$b-$be-$r.json 2> $RES/$a-$b-$be-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":")
    line, hs = f"{a}>{b}", set()
    for be in ("auto", "cpu", "rt-pipeline"):
        ts, ran = [], set()
        for r in (1, 2):
            try:
                j = json.load(open(f"{R}/{a}-{b}-{be}-{r}.json"))
            except Exception as e:
                ts.append(None); continue
            ts.append(round(j["kept_median_ms"]["total"], 2)); ran.add(j["backend"]); hs.add(j["hausdorff"])
            q = j["points"]; t = j["triangles"]
        line += f" | {be} {ts} ran {sorted(ran)}"
    print(line, f"| queries {q} triangles {t} | H {sorted(hs)}")
PY
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_engine_tests --gtest_filter='DeviceInput.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E 'PASSED|FAILED|SKIPPED' $RES/engine_tests.txt | tr '\n' ' ')"
