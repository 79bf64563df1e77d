#!/usr/bin/env bash
# Session 18, call 2: the leaf split of both sets side by side
# (IndexBuild::splitLeaves) against c9ca2e4 (before): the rows that split
# (crowded, Cauchy) --verify'd, then before / after / CuPy's KDTree
# alternated in 3 rounds; docs/bench/gpu.md's rows one-shot, before / after,
# 2 rounds; the submissions of a crowded-200k call counted.
set -uo pipefail
B=.devs; D=$B/data; S=/tmp/ds; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W $S /tmp/res
trap "cp $OUT/*.jsonl $OUT/*.txt /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
rows="crowded-200k crowded-2M cauchy-200k cauchy-1M"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for r in $rows; do
  $B/rthdist $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --verify --json --quiet > /tmp/res/verify_$r.json 2>&1
  echo "verify $r exit $? $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=d['verify']; print(d['hausdorff'], v['ok'], v['max_abs_diff'])" /tmp/res/verify_$r.json 2>&1 | head -c 200)"
done
for round in 1 2 3; do
  python3 $here/gpu_density_peers.py $W $rows --runs 3 >> $OUT/cupy.jsonl 2>> $OUT/errors.txt
  for build in before after; do
    bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
    for r in $rows; do
      $bin $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
    done
  done
done
python3 - $OUT/density.jsonl $OUT/cupy.jsonl <<'PY'
import json,sys,collections
r=collections.defaultdict(list); c=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); m=d['median_ms']; r[(d['case'],d['build'])].append((round(m['wall'],2), round(m['gpu_sum'],3), round(m['index'],2), round(m['gpu_index'],3)))
for l in open(sys.argv[2]):
    d=json.loads(l)
    if d.get('tool')=='cupy_kdtree' and 'median_s' in d: c[d['case']].append(round(d['median_s']*1e3,1))
for (n,b),v in sorted(r.items()):
    print(n, b, 'wall/gpu/index/gpu_index', v, 'cupy ms', c.get(n), 'ratios', [round(y/x[0],1) for x in v for y in c.get(n,[])][:6])
PY
for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  RTHDIST_SUBMIT_TRACE=1 $bin $W/crowded-200k_a.ply $W/crowded-200k_b.ply --backend rt-pipeline --name crowded-200k --runs 3 --warmup 2 --no-verify 2> $OUT/trace_$build.txt > /dev/null
  echo "crowded-200k $build: $(grep -c 'rthdist submit' $OUT/trace_$build.txt) submissions in 5 calls"
done
source $here/gpu_rows.sh
for round in 1 2; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for c in "${cases[@]}"; do set -- $c
    $bin "$2" "$3" --name "$1" --backend rt-pipeline --runs 5 --warmup 2 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/rows.jsonl
  done
done; done
python3 - $OUT/rows.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d.get('name', d.get('case')),d['build'])].append(d)
for (n,b),v in sorted(rows.items()):
    print(n, b, [(round(x['median_ms']['wall'],2), round(x['median_ms']['gpu_sum'],3)) for x in v], v[0].get('hausdorff'), v[0].get('agree'))
PY
