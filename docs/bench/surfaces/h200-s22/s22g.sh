#!/usr/bin/env bash
# Session 22, call 7 (one H200, 16 cores): the CPU backend's surface search
# of the session's last build (97a2358: a directed search past 2^22 queries
# keeps input order, per point and smaller sets in Morton order) against
# the build of 5241456, on call 4's scale row, kept Engines, two rounds of
# 5 alternated.
source tools/bench/device_prelude.sh
B=.devt
M=$B/dragon-res3.ply
for n in 1000000 10000000; do
  python3 tools/bench/sample_surface.py $B/dragon-res2.ply.gz $n 1 /tmp/r$n.ply || exit 1
done
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 200 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for n in 1000000 10000000; do
  for r in 1 2; do
    for v in before after; do
      bin=$B/rthdist-surface-bench; [ $v = before ] && bin=$B/rthdist-surface-bench-before
      run cpu-$v-$n-$r $bin /tmp/r$n.ply $M --backend cpu --runs 5 --warmup 1 --no-verify
      run cpu-pp-$v-$n-$r $bin /tmp/r$n.ply $M --backend cpu --runs 5 --warmup 1 --no-verify --per-point
    done
  done
done
python3 - <<'PY'
import json, glob, os
for f in sorted(glob.glob("/tmp/res/*.json")):
    j = json.load(open(f))
    print(os.path.basename(f)[:-5], "kept %.1f" % j["kept_median_ms"]["total"], [round(x, 1) for x in j["kept_total_ms_all"]], "h %.17g" % j["hausdorff"])
PY
