#!/usr/bin/env bash
# Session 22, call 3 (one H200, 16 cores; build 603cbd6): per-point
# distances to a surface, 10M samples of the Dragon's surface (seed 1) to
# dragon_vrip_res2's triangles: the CLI (a process a run: its statistics now
# by selection, not a sort) on the cpu and rt-pipeline backends, then
# rthdist-surface-bench's kept Engines (--per-point, and --distances-only as
# the evaluation asks), each checked against the CPU backend's entries.
source tools/bench/device_prelude.sh
B=.devs
M=$B/data/dragon-res2.ply
python3 tools/bench/sample_surface.py $B/data/dragon_vrip.ply.gz 10000000 1 /tmp/d10m.ply || exit 1
run() {  # name, then the command
  local name=$1; shift
  /usr/bin/time -f "%e s %M KB" timeout 150 "$@" > $RES/$name.json 2> $RES/$name.err
  echo "$name exit $? $(tail -1 $RES/$name.err)"
}
for r in 1 2 3; do
  for b in cpu rt-pipeline; do
    run cli-pp-$b-$r $B/rthdist /tmp/d10m.ply $M --surface b --backend $b --per-point --json
  done
done
run kept-pp-rt-pipeline $B/rthdist-surface-bench /tmp/d10m.ply $M --backend rt-pipeline --per-point --runs 5 --warmup 1
run kept-pp-cpu $B/rthdist-surface-bench /tmp/d10m.ply $M --backend cpu --per-point --runs 5 --warmup 1 --no-verify
run kept-dist-rt-pipeline $B/rthdist-surface-bench /tmp/d10m.ply $M --backend rt-pipeline --per-point --distances-only --runs 5 --warmup 1
run kept-dist-cpu $B/rthdist-surface-bench /tmp/d10m.ply $M --backend cpu --per-point --distances-only --runs 5 --warmup 1 --no-verify
run kept-plain-rt-pipeline $B/rthdist-surface-bench /tmp/d10m.ply $M --backend rt-pipeline --runs 5 --warmup 1 --no-verify
run kept-plain-cpu $B/rthdist-surface-bench /tmp/d10m.ply $M --backend cpu --runs 5 --warmup 1 --no-verify
python3 - <<'PY'
import json, glob, os, statistics
R = "/tmp/res"
for f in sorted(glob.glob(R + "/cli-*.json")):
    j = json.load(open(f)); t = j["timings_ms"]
    print(os.path.basename(f), "total %.0f wall %.0f load %.0f" % (t["total"], t["wall"], t["load"]), {k: round(v, 1) for k, v in t["stages"].items() if v})
for f in sorted(glob.glob(R + "/kept-*.json")):
    j = json.load(open(f))
    print(os.path.basename(f), "setup %.0f" % j["setup_ms"], "kept", {k: round(v, 1) for k, v in j["kept_median_ms"].items() if v}, "agree", j["agree"], "ref", j.get("cpu_reference"), "counters", j["counters"])
PY
