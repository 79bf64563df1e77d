#!/usr/bin/env bash
# Session 17, call 5: the rest of issue 33's family beside CuPy's KDTree in
# one call (far-0.1mm and far-10mm one/both, crowded-2M, cluster-5M,
# cauchy-1M; build 5e60bd8, 2 rounds, CuPy median of 3), then the
# submissions' trace of three small rows (RTHDIST_SUBMIT_TRACE=1).
set -uo pipefail
B=.devs; D=$B/data; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W /tmp/res
trap "cp $OUT/*.jsonl $OUT/*.txt /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
rows="far-0.1mm-one far-0.1mm-both far-10mm-one far-10mm-both crowded-2M cluster-5M cauchy-1M crowded-200k cluster-200k"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for r in $rows; do
  $B/rthdist $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --verify --json --quiet > /tmp/res/verify_$r.json 2>&1
  echo "verify $r exit $? $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=d['verify']; print(d['hausdorff'], v['ok'], v['max_abs_diff'])" /tmp/res/verify_$r.json 2>&1 | head -c 200)"
done
for round in 1 2; do
  python3 $here/gpu_density_peers.py $W $rows --runs 3 >> $OUT/cupy.jsonl 2>> $OUT/errors.txt
  for r in $rows; do
    $B/rthdist-bench $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
  done
done
python3 - $OUT/density.jsonl $OUT/cupy.jsonl <<'PY'
import json,sys,collections
r=collections.defaultdict(list); g=collections.defaultdict(list); c=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); r[d['case']].append(d['median_ms']['wall']); g[d['case']].append(d['median_ms']['gpu_sum'])
for l in open(sys.argv[2]):
    d=json.loads(l)
    if d.get('tool')=='cupy_kdtree' and 'median_s' in d: c[d['case']].append(d['median_s']*1e3)
for n in r:
    print(n, 'rthdist wall ms', [round(x,2) for x in r[n]], 'gpu', [round(x,3) for x in g[n]], 'cupy ms', [round(x,1) for x in c.get(n,[])],
          'ratio', [round(y/x,1) for x in r[n] for y in c.get(n,[])][:4])
PY
for r in crowded-200k cluster-200k; do
  RTHDIST_SUBMIT_TRACE=1 $B/rthdist-bench $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 3 --warmup 2 --no-verify 2> $OUT/trace_$r.txt > /dev/null
  echo "$r: $(grep -c 'rthdist submit' $OUT/trace_$r.txt) submissions in 5 calls"; grep -v "rthdist buffer" $OUT/trace_$r.txt | tail -8
done
RTHDIST_SUBMIT_TRACE=1 $B/rthdist-bench $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz --backend rt-pipeline --name dragon-res2 --runs 3 --warmup 2 --no-verify 2> $OUT/trace_dragon.txt > /dev/null
echo "dragon-res2: $(grep -c 'rthdist submit' $OUT/trace_dragon.txt) submissions in 5 calls"; grep -v "rthdist buffer" $OUT/trace_dragon.txt | tail -6
