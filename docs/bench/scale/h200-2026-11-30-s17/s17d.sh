#!/usr/bin/env bash
# Session 17, call 4: CuPy's KDTree on the density rows in the same call as
# the new build's rthdist-bench (3 processes a row, alternated with CuPy's
# rounds), then the scale suite (PROCS=2, --verify) on the new build.
set -uo pipefail
B=.devs; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W /tmp/res
trap "cp $OUT/*.jsonl /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
rows="cluster-200k cluster-1M far-1mm-one far-1mm-both crowded-200k cauchy-200k"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for round in 1 2; do
  python3 $here/gpu_density_peers.py $W $rows --runs 5 >> $OUT/cupy.jsonl 2>> $OUT/errors.txt
  for r in $rows; do
    $B/rthdist-bench $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
  done
done
python3 - $OUT/density.jsonl $OUT/cupy.jsonl <<'PY'
import json,sys,collections
r=collections.defaultdict(list); c=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); r[d['case']].append(d['median_ms']['wall'])
for l in open(sys.argv[2]):
    d=json.loads(l)
    if d.get('tool')=='cupy_kdtree' and 'median_s' in d: c[d['case']].append(d['median_s']*1e3)
for n in r:
    print(n, 'rthdist wall ms', [round(x,2) for x in r[n]], 'cupy ms', [round(x,1) for x in c.get(n,[])],
          'ratio', [round(y/x,1) for x in r[n] for y in c.get(n,[])][:4])
PY
PROCS=2 bash tools/bench/gpu_scale_suite.sh $B /tmp/res/suite > /tmp/res/suite.txt 2>&1
echo "suite exit $?"; cat /tmp/res/suite/lines.txt | cut -c1-220
