#!/usr/bin/env bash
# Session 29, call 2 (one H200, 16 cores): the proof's passes over the
# device's distances, a kept rt-pipeline Engine (rthdist-surface-bench
# --runs 9 --warmup 2 --no-verify, all host threads), 3 rounds alternated:
#   base     4c1acc3 (sb-new: the read-back's pass, then the proof's pass for
#            q* and a second pass over every query for the band)
#   summary  the read-back notes each chunk's largest (core::SearchedTops),
#            the band reads only the chunks that can reach L (sb-exp)
#   min4096  summary, light passes in chunks of >= 4,096 (EXP_MINCHUNK: an
#            experiment's knob, not in the library; 2,048 in it)
#   min8192  the same with 8,192
# Then sb-exp's stderr marks (CTRACE=1) and the GPU surface tests on
# rt-pipeline with the validation layer (gst: the committed change).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
for f in sb-new sb-exp gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 bunny-res2:bunny dragon-res4:dragon-res2"
run() {  # variant a b round
  local v=$1 a=$2 b=$3 r=$4 bin=$B/sb-exp env=()
  case $v in base) bin=$B/sb-new ;; min4096) env=(EXP_MINCHUNK=4096) ;; min8192) env=(EXP_MINCHUNK=8192) ;; esac
  env "${env[@]}" timeout 60 $bin $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/p-$a-$b-$v-$r.json 2> $RES/p-$a-$b-$v-$r.err
}
for r in 1 2 3; do
  for row in $rows; do
    for v in base summary min4096 min8192; do run $v ${row%%:*} ${row##*:} $r; done
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics, collections
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); hs = set()
    for v in ("base", "summary", "min4096", "min8192"):
        tot, st = [], collections.defaultdict(list)
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/p-{a}-{b}-{v}-{r}.json"))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"]); hs.add(j["hausdorff"])
            for s in ("frame", "upload", "device", "gpu", "readback", "certify"): st[s].append(k[s])
        print(f"{a}>{b} {v:8s} totals", ["%.3f" % x for x in tot], "median %.3f" % statistics.median(tot) if tot else "-",
              " ".join("%s %.3f" % (s, statistics.median(x)) for s, x in st.items()))
    print("   H", sorted(hs))
PY
for row in bunny:bunny-res4 bunny:bunny-res3; do
  a=${row%%:*}; b=${row##*:}
  CTRACE=1 RTHDIST_SUBMIT_TRACE=1 timeout 60 $B/sb-exp $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/trace-$a-$b.json 2> $RES/trace-$a-$b.err
  tail -13 $RES/trace-$a-$b.err | head -12
done
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
grep -c "Validation" $RES/gpu_surface_tests.txt
