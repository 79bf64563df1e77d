#!/usr/bin/env bash
# Session 29, call 1 (one H200, 16 cores), 4c1acc3:
#  A. where a kept rt-pipeline Engine's points-to-surface call spends its
#     ~0.5 ms on bunny>res3 and bunny>res4 (bunny-res4>bunny beside them):
#     rthdist-surface-bench --runs 9 --warmup 2 --no-verify by host threads
#     0 (16) / 8 / 4 / 2, 3 rounds alternated; then a build with stderr marks
#     (sb-trace: "certify <mark> <ms since the proof began>", "gpu route: <mark>
#     <ms since the route began>", "engine: <mark> <ms>"; CTRACE=1) and the
#     submissions' own marks (RTHDIST_SUBMIT_TRACE=1).
#  B. surface to surface on the CPU backend, 16 threads, in one process
#     (rthdist-surface-bench --surfaces 0: the default tolerance, 1e-4 of the
#     diagonal) against CGAL 5.5's bounded_error_Hausdorff_distance at the same
#     tolerance (one thread: CGAL 5.5's parallel version needs METIS and an
#     internal macro), 3 rounds alternated.
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
for f in sb-new sb-trace surface-cgal; do xz -dc .devx/$f.xz > $B/$f; chmod +x $B/$f; done
rows="bunny:bunny-res3 bunny:bunny-res4 bunny-res4:bunny"
for r in 1 2 3; do
  for row in $rows; do
    a=${row%%:*}; b=${row##*:}
    for t in 0 8 4 2; do
      timeout 60 $B/sb-new $M/$a.ply $M/$b.ply --backend rt-pipeline --threads $t --runs 9 --warmup 2 --no-verify > $RES/p-$a-$b-t$t-$r.json 2> $RES/p-$a-$b-t$t-$r.err
    done
  done
done
for row in bunny:bunny-res3 bunny:bunny-res4; do
  a=${row%%:*}; b=${row##*:}
  for t in 0 4; do
    CTRACE=1 RTHDIST_SUBMIT_TRACE=1 timeout 60 $B/sb-trace $M/$a.ply $M/$b.ply --backend rt-pipeline --threads $t --runs 9 --warmup 2 --no-verify > $RES/trace-$a-$b-t$t.json 2> $RES/trace-$a-$b-t$t.err
  done
done
python3 - <<'PY'
import json, glob, statistics, collections
R = "/tmp/res"
for row in ("bunny-bunny-res3", "bunny-bunny-res4", "bunny-res4-bunny"):
    for t in (0, 8, 4, 2):
        tot, st = [], collections.defaultdict(list)
        for r in (1, 2, 3):
            try: j = json.load(open(f"{R}/p-{row}-t{t}-{r}.json"))
            except Exception: continue
            k = j["kept_median_ms"]; tot.append(k["total"])
            for s in ("frame", "upload", "device", "gpu", "readback", "certify", "search"): st[s].append(k[s])
        print(row, "threads", t, "totals", ["%.3f" % x for x in tot], "median %.3f" % statistics.median(tot) if tot else "-",
              " ".join("%s %.3f" % (s, statistics.median(v)) for s, v in st.items()))
PY
rows2="bunny:bunny-res2 bunny-res2:bunny-res3 bunny-res3:bunny-res4 dragon-res2:dragon-res3 dragon-res3:dragon-res4 bunny-res2:bunny-res2-t0.1 bunny-res2:bunny-res2-t0.01 bunny-res2:bunny-res2-t0.001"
for r in 1 2 3; do
  for row in $rows2; do
    a=${row%%:*}; b=${row##*:}
    timeout 120 $B/sb-new $M/$a.ply $M/$b.ply --surfaces 0 --backend cpu --runs 5 --warmup 1 > $RES/s-$a-$b-$r.json 2> $RES/s-$a-$b-$r.err
    tol=$(python3 -c "import json;print(repr(json.load(open('$RES/s-$a-$b-$r.json'))['tolerance']))" 2>/dev/null)
    timeout 200 $B/surface-cgal surfaces $M/$a.ply $M/$b.ply --tolerance ${tol:-1e-5} --repeat 3 > $RES/c-$a-$b-$r.txt 2> $RES/c-$a-$b-$r.err
  done
done
python3 - "$rows2" <<'PY'
import json, sys, statistics, re
R = "/tmp/res"
for row in sys.argv[1].split():
    a, b = row.split(":"); ours, cg, bounds = [], [], set()
    for r in (1, 2, 3):
        try:
            j = json.load(open(f"{R}/s-{a}-{b}-{r}.json")); ours.append(j["median_ms"]["total"]); bounds.add(tuple(j["bounds"]))
        except Exception: pass
        try: cg += json.load(open(f"{R}/c-{a}-{b}-{r}.txt"))["total_ms"]
        except Exception: pass
    mo = statistics.median(ours) if ours else float("nan"); mc = statistics.median(cg) if cg else float("nan")
    print(f"{a}|{b}: rthdist cpu16 {mo:.2f} ms {['%.2f' % x for x in ours]}  cgal 1t {mc:.2f} ms ({len(cg)} runs)  ratio {mc / mo:.1f}x  bounds {sorted(bounds)}")
PY
grep -h "" $RES/c-bunny-res3-bunny-res4-1.txt | head -5
