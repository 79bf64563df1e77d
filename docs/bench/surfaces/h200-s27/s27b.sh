#!/usr/bin/env bash
# Session 27, call 2 (one H200, 16 cores): the committed rule (56aac7f:
# lanes on a GPU up to ~2^18 threads, descend-only up to 32,768 queries)
# against the rule before it (488a3a3), same binary: "before" is one lane
# (RTHDIST_SURFACE_TAIL_LANES=1, the shader's old path) with the radii
# forced (RTHDIST_SURFACE_DESCEND=0) on the rows the old rule searched by
# radii (more than 1,024 queries and 4,096 triangles). Kept Engines of
# rt-pipeline, `rthdist-surface-bench --runs 9 --warmup 2`, 3 rounds
# alternated; then lane sweeps of the many-query descending rows, and one
# traced call (RTHDIST_SUBMIT_TRACE=1).
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx; M=$B/m
# row = points:mesh:old-rule-descended (1) or not (0)
rows="bunny:bunny-res3:1 bunny:bunny-res4:1 bunny-res4:bunny:1 bunny:bunny-res2:0 dragon-res4:dragon:0 armadillo:armadillo-dec:0 armadillo-dec:armadillo:0 bunny-scans:bunny:0 dragon:dragon-res2:0 dragon:dragon-res3:0 dragon:dragon-res4:0"
bench() {  # points mesh out
  timeout 120 $B/rthdist-surface-bench $M/$1.ply $M/$2.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify > $3.json 2> $3.err
}
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); IFS=: read -r a b old <<< "$row"
    if [ "$old" = 1 ]; then RTHDIST_SURFACE_TAIL_LANES=1 bench $a $b $RES/s$i-before-$r
    else RTHDIST_SURFACE_TAIL_LANES=1 RTHDIST_SURFACE_DESCEND=0 bench $a $b $RES/s$i-before-$r; fi
    bench $a $b $RES/s$i-after-$r
  done
done
python3 - "$rows" <<'PY'
import json, sys, statistics
R = "/tmp/res"
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b, _ = row.split(":"); out, hs, med = f"{a} > {b}", set(), {}
    for v in ("before", "after"):
        parts, tot = [], []
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/s{i}-{v}-{r}.json"))
            except Exception: parts.append("-"); continue
            k = j["kept_median_ms"]; c = j["counters"]; hs.add(j["hausdorff"]); tot.append(k["total"])
            parts.append("%.3f [gpu %.3f radii %d lanes %d]" % (k["total"], k["gpu"], c["radii"], c["tail_lanes"]))
        med[v] = statistics.median(tot) if tot else float("nan")
        out += f"\n   {v:6s} " + " / ".join(parts)
    print(out, "\n   median of rounds: before %.3f after %.3f (%.2fx)" % (med["before"], med["after"], med["before"] / med["after"]), " H", sorted(hs))
PY
sweep() {  # points mesh lanes...
  local a=$1 b=$2; shift 2
  for l in "$@"; do
    RTHDIST_SURFACE_DESCEND=1 RTHDIST_SURFACE_TAIL_LANES=$l bench $a $b $RES/sweep-$a-$b-$l
    python3 -c "import json,sys; j=json.load(open(sys.argv[1])); k=j['kept_median_ms']; print(sys.argv[2], 'lanes', sys.argv[3], 'total %.3f gpu %.3f certify %.3f frame %.3f upload %.3f' % (k['total'], k['gpu'], k['certify'], k['frame'], k['upload']))" $RES/sweep-$a-$b-$l.json "$a>$b" $l 2>&1 | tail -1
  done
}
sweep bunny bunny-res4 1 2 4 8 16
sweep bunny bunny-res3 1 2 4 8 16
sweep bunny bunny-res2 1 2 4 8 16
sweep armadillo armadillo-dec 1 2 4 8 16 32
sweep armadillo-dec armadillo 8 16 32
sweep bunny-scans bunny 1 2 4
RTHDIST_SUBMIT_TRACE=1 timeout 60 $B/rthdist-surface-bench $M/bunny.ply $M/bunny-res4.ply --backend rt-pipeline --runs 3 --warmup 1 --no-verify > $RES/trace.json 2> $RES/trace.err; tail -n 6 $RES/trace.err
