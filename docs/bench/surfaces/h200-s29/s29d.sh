#!/usr/bin/env bash
# Session 29, call 4 (one H200, 16 cores): the GPU surface search frames
# a call's queries straight into its upload buffer (core::FramedQueries:
# no framed copy and no pass to copy it), sb-fq, against 7a5e644 (sb-sum),
# all host threads, 3 rounds alternated: kept rt-pipeline Engines
# (rthdist-surface-bench --runs 9 --warmup 2 --no-verify); then the GPU
# surface tests on rt-pipeline with the validation layer (gst, sb-fq's code).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
for f in sb-sum sb-fq gst; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
gpu="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny bunny:bunny-res2 dragon-res4:dragon-res2"
cpu=""
s2s=""
for r in 1 2 3; do
  for v in sb-sum sb-fq; do
    for row in $gpu; do a=${row%%:*}; b=${row##*:}
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $RES/g-$a-$b-$v-$r.json 2> $RES/g-$a-$b-$v-$r.err; done
    for row in $cpu; do a=${row%%:*}; b=${row##*:}
      timeout 60 $B/$v $M/$a.ply $M/$b.ply --backend cpu --runs 9 --warmup 2 --no-verify > $RES/c-$a-$b-$v-$r.json 2> $RES/c-$a-$b-$v-$r.err; done
    for row in $s2s; do a=${row%%:*}; b=${row##*:}
      timeout 120 $B/$v $M/$a.ply $M/$b.ply --surfaces 0 --backend cpu --runs 7 --warmup 2 > $RES/s-$a-$b-$v-$r.json 2> $RES/s-$a-$b-$v-$r.err; done
  done
done
python3 - "$gpu" "$cpu" "$s2s" <<'PY'
import json, sys, statistics, collections
R = "/tmp/res"
for kind, rows, key in (("g", sys.argv[1], "kept_median_ms"), ("c", sys.argv[2], "kept_median_ms"), ("s", sys.argv[3], "median_ms")):
    for row in rows.split():
        a, b = row.split(":"); vals = set(); line = f"{kind} {a}>{b}:"
        for v in ("sb-sum", "sb-fq"):
            tot, st = [], collections.defaultdict(list)
            for r in (1, 2, 3):
                try: j = json.load(open(f"{R}/{kind}-{a}-{b}-{v}-{r}.json"))
                except Exception: continue
                k = j[key]; tot.append(k["total"]); vals.add(str(j.get("hausdorff", j.get("bounds"))))
                for s in ("frame", "upload", "device", "readback", "certify", "search"):
                    if s in k: st[s].append(k[s])
            line += f"\n   {v:8s} " + " ".join("%.3f" % x for x in tot) + (" median %.3f" % statistics.median(tot) if tot else "") + "  " + " ".join("%s %.3f" % (s, statistics.median(x)) for s, x in st.items())
        print(line, "\n   values", sorted(vals))
PY
export VK_LAYER_PATH=$PWD/.devx/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 240 $B/gst > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
