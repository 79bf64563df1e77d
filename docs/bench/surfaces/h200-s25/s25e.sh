#!/usr/bin/env bash
# Session 25, call 5 (one H200, 16 cores): the CPU backend's point-to-surface
# search with its queries always in Morton order (a temporary switch,
# RTHDIST_X_ALWAYS_SORT, in sb-sort / rthdist-sort; not in main) against the
# rule of cpu/query_order.cpp (a mesh's vertices count as in space order and
# keep their order): kept Engines (rthdist-surface-bench --backend cpu --runs
# 9 --warmup 2) and one-shot CLI processes (--surface b --backend cpu, the
# sort's cost included), 3 rounds alternated.
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx; M=$B/m; D=$B/data
rows="$M/bun_zipper.ply:$M/bun_zipper_res2.ply $M/bun_zipper.ply:$M/bun_zipper_res3.ply $M/bun_zipper.ply:$M/bun_zipper_res4.ply $D/dragon_vrip.ply.gz:$D/dragon_vrip_res2.ply.gz $D/dragon_vrip.ply.gz:$M/dragon_vrip_res3.ply.gz $D/dragon_vrip.ply.gz:$M/dragon_vrip_res4.ply.gz"
for r in 1 2 3; do
  i=0
  for row in $rows; do
    i=$((i + 1)); a=${row%%:*}; b=${row##*:}
    for v in rule sort; do
      env=""; [ $v = sort ] && env="RTHDIST_X_ALWAYS_SORT=1"
      env $env timeout 120 $B/sb-sort $a $b --backend cpu --runs 9 --warmup 2 --no-verify > $RES/k$i-$v-$r.json 2> $RES/k$i-$v-$r.err
      env $env timeout 120 $B/rthdist-sort $a $b --surface b --directed --backend cpu --json > $RES/c$i-$v-$r.json 2> $RES/c$i-$v-$r.err
    done
  done
done
python3 - "$rows" <<'PY'
import json, sys, os
R = "/tmp/res"
def get(f):
    try: return json.load(open(f))
    except Exception: return None
for i, row in enumerate(sys.argv[1].split(), 1):
    a, b = row.split(":"); out, hs = f"{os.path.basename(a)} > {os.path.basename(b)}", set()
    for v in ("rule", "sort"):
        ks, cs = [], []
        for r in (1, 2, 3):
            j = get(f"{R}/k{i}-{v}-{r}.json")
            if j: ks.append("%.2f" % j["kept_median_ms"]["total"]); hs.add(j["hausdorff"])
            c = get(f"{R}/c{i}-{v}-{r}.json")
            if c:
                t = c.get("timings_ms", c.get("time_ms", {}))
                cs.append("%.2f" % t.get("total", -1) if isinstance(t, dict) else "?")
        out += f" | {v}: kept {'/'.join(ks)} cli total {'/'.join(cs)}"
    print(out, "| H", sorted(hs))
PY
