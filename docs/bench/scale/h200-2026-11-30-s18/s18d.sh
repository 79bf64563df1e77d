#!/usr/bin/env bash
# Session 18, call 4: 30091d3 (narrowPair decides strays of their own both
# ways from the boxes, before any pass) against ebccadc (before): the far
# rows that do (far-*-both) or do not (far-1mm-one, cluster-200k) narrow,
# --verify'd, then before / after alternated, 3 rounds; the scale suite's
# cluster-100M with BEFORE (a before process ahead of each after one,
# PROCS=3), then the other four cases on the new build (PROCS=2).
set -uo pipefail
B=.devs; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W /tmp/res
trap "cp $OUT/*.jsonl $OUT/*.txt /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
rows="far-1mm-both far-10mm-both far-1mm-one cluster-200k"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for r in $rows; do
  $B/rthdist $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --verify --json --quiet > /tmp/res/verify_$r.json 2>&1
  echo "verify $r exit $? $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=d['verify']; c=d['counters']; print(d['hausdorff'], v['ok'], v['max_abs_diff'], 'narrowed', c['a_to_b']['narrowed_targets'], c['b_to_a']['narrowed_targets'])" /tmp/res/verify_$r.json 2>&1 | head -c 200)"
done
for round in 1 2 3; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for r in $rows; do
    $bin $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
  done
done; done
python3 - $OUT/density.jsonl <<'PY'
import json,sys,collections
r=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); m=d['median_ms']; r[(d['case'],d['build'])].append((round(m['wall'],2), round(m['gpu_sum'],3)))
for (n,b),v in sorted(r.items()): print(n, b, 'wall/gpu', v)
PY
BEFORE=$PWD/$B/rthdist-before PROCS=3 bash $here/gpu_scale_suite.sh $B /tmp/res/suite_cluster cluster-100M > /tmp/res/suite_cluster.txt 2>&1
echo "cluster suite exit $?"; cut -c1-420 /tmp/res/suite_cluster/lines.txt
PROCS=2 bash $here/gpu_scale_suite.sh $B /tmp/res/suite crowded-20M torus-300x400 shell-400x400 cube-300x300 > /tmp/res/suite.txt 2>&1
echo "suite exit $?"; cut -c1-420 /tmp/res/suite/lines.txt
