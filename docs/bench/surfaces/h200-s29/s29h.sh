#!/usr/bin/env bash
# Session 29, call 9 (one H200, 16 cores): the host's topology (lscpu,
# the vCPUs' core siblings) and bunny>res4 / bunny>res3 on 90b6f7c
# (sb-fq), kept rt-pipeline Engines, --runs 9 --warmup 2 --no-verify, by
# host threads (16 = all, 12, 8) and with the pool polling 1,000 us, 3
# rounds alternated: which of the host passes' costs follow the cores.
BUNDLE=.devx
source tools/bench/device_prelude.sh
lscpu | grep -E "^(Model name|Socket|Core|Thread|NUMA node|CPU\(s\))"
for c in 0 1 2 8 9; do echo "cpu$c siblings $(cat /sys/devices/system/cpu/cpu$c/topology/thread_siblings_list 2>/dev/null) core $(cat /sys/devices/system/cpu/cpu$c/topology/core_id 2>/dev/null)"; done
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
xz -dc .devx/sb-fq.xz > $B/sb; chmod +x $B/sb
for r in 1 2 3; do
  for row in bunny:bunny-res4 bunny:bunny-res3; do a=${row%%:*}; b=${row##*:}
    for v in t16 t12 t8 t16spin t12spin; do
      t=${v%spin}; t=${t#t}; env=(); [ "$v" != "${v%spin}" ] && env=(RTHDIST_POOL_SPIN_US=1000)
      env "${env[@]}" timeout 60 $B/sb $M/$a.ply $M/$b.ply --backend rt-pipeline --threads $t --runs 9 --warmup 2 --no-verify > $RES/$a-$b-$v-$r.json 2> $RES/$a-$b-$v-$r.err
    done
  done
done
python3 - <<'PY'
import json, statistics
R = "/tmp/res"
for row in ("bunny-bunny-res4", "bunny-bunny-res3"):
    for v in ("t16", "t12", "t8", "t16spin", "t12spin"):
        ks = [json.load(open(f"{R}/{row}-{v}-{r}.json"))["kept_median_ms"] for r in (1, 2, 3)]
        med = lambda s: statistics.median(k[s] for k in ks)
        print(f"{row} {v:8s} " + " ".join("%.3f" % k["total"] for k in ks) + "  median %.3f upload %.3f device %.3f readback %.3f certify %.3f" % (med("total"), med("upload"), med("device"), med("readback"), med("certify")))
PY
