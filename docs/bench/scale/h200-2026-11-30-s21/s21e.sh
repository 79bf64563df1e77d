#!/usr/bin/env bash
# Session 21, call 5 (one H200, 16 cores): (1) the CLI on the Dragon pair
# (gzip'd ASCII PLY) under auto (the CPU backend since 6feecd0), 6feecd0
# (before: zlib inflates the files) against this build (libdeflate
# inflates them whole), 5 rounds alternated; (2) rthdist-bench on
# docs/bench/gpu.md's dragon-res2 and dragon-t0.5 rows, 340211b (before)
# against this build, 4 rounds alternated, 15 runs after 5 warm-ups each.
source tools/bench/device_prelude.sh
B=.devs; D=$B/data
ldd $B/rthdist | grep -E "deflate|not found"
pair="$D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz"
mkdir -p $RES/cli $RES/rows
one() {  # label binary
  timeout 60 $B/$2 --json --quiet $pair > $RES/cli/$1.json 2> $RES/cli/$1.err
  echo "$1 $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print(d['backend'], d['hausdorff'], 'load', round(t['load'],1), 'total', round(t['total'],1), 'wall', round(t['wall'],1))" $RES/cli/$1.json 2>&1 | head -c 200)"
}
one warm_before rthdist-before > /dev/null; one warm_after rthdist > /dev/null
for r in 1 2 3 4 5; do one before_$r rthdist-before; one after_$r rthdist; done
S=/tmp/rthdist-samples; mkdir -p $S
python3 - "$D/dragon_vrip.ply.gz" "$S" tools/bench <<'PY'
import sys; sys.path.insert(0, sys.argv[3])
from ply_points import read_ply, write_ply
a = read_ply(sys.argv[1]); b = a.copy(); b[:, 0] += (float(a[:, 0].max()) - float(a[:, 0].min())) * 0.5
write_ply("%s/dragon_t0.5.ply" % sys.argv[2], b)
PY
for r in 1 2 3 4; do
  for build in before after; do
    bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
    for c in "dragon-res2 $pair" "dragon-t0.5 $D/dragon_vrip.ply.gz $S/dragon_t0.5.ply"; do
      set -- $c
      timeout 60 $bin $2 $3 --name $1 --backend rt-pipeline --runs 15 --warmup 5 --no-verify 2>> $RES/rows/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$r; print(json.dumps(d))" >> $RES/rows/ab.jsonl
    done
  done
done
python3 - $RES/rows/ab.jsonl <<'PY'
import json, sys, statistics
rows = [json.loads(l) for l in open(sys.argv[1])]
for case in ("dragon-res2", "dragon-t0.5"):
    for build in ("before", "after"):
        v = [r["median_ms"]["total"] for r in rows if r["case"] == case and r["build"] == build]
        g = [r["median_ms"]["gpu_sum"] for r in rows if r["case"] == case and r["build"] == build]
        print(case, build, "total by round", [round(x, 3) for x in v], "median", round(statistics.median(v), 3), "gpu", round(statistics.median(g), 3))
PY
