#!/usr/bin/env bash
# Session 17, call 3: the narrowing's host passes (packed-float scan, tasks
# of 2^14 points) and the narrowed calls on the device ingest, against
# 78f4947 (before): the density rows, 3 rounds alternated (the new build
# also with RTHDIST_NARROW_HOST_BOUNDS=1), every row --verify'd; then
# docs/bench/gpu.md's rows one-shot and per-point, 2 rounds alternated.
set -uo pipefail
B=.devs; D=$B/data; S=/tmp/rthdist-samples; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W $S /tmp/res
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
for r in $rows; do for nh in 0 1; do
  RTHDIST_NARROW_HOST_BOUNDS=$nh $B/rthdist $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --verify --json --quiet > /tmp/res/verify_${r}_$nh.json 2>&1
  echo "verify $r hostbounds=$nh exit $? $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=d['verify']; print(d['hausdorff'], v['ok'], v['max_abs_diff'])" /tmp/res/verify_${r}_$nh.json 2>&1 | head -c 200)"
done; done
for round in 1 2 3; do for build in before after after-hb; do
  bin=$B/rthdist-bench; nh=0
  [ $build = before ] && bin=$B/rthdist-bench-before
  [ $build = after-hb ] && nh=1
  for r in $rows; do
    RTHDIST_NARROW_HOST_BOUNDS=$nh $bin $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
  done
done; done
python3 - $OUT/density.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d.get('name', d.get('case')),d['build'])].append(d)
for (n,b),v in sorted(rows.items()):
    m=v[-1]['median_ms']
    print(n, b, [round(x['median_ms']['wall'],2) for x in v], 'gpu', round(m['gpu_sum'],3), 'upload', round(m['upload'],2), 'pieces', round(m['pieces'],2), 'index', round(m['index'],2), 'cull', round(m['cull'],2), v[0].get('hausdorff'))
PY
source $here/gpu_rows.sh
for round in 1 2; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for c in "${cases[@]}"; do set -- $c
    for pp in "" --per-point; do
      $bin "$2" "$3" --name "$1" --backend rt-pipeline --runs 5 --warmup 2 $pp 2>> $OUT/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; d['per_point']='$pp'!=''; print(json.dumps(d))" >> $OUT/rows.jsonl
    done
  done
done; done
python3 - $OUT/rows.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d.get('name', d.get('case')),d['per_point'],d['build'])].append(d)
for (n,pp,b),v in sorted(rows.items()):
    print(n, 'per-point' if pp else 'one-shot', b, [(round(x['median_ms']['wall'],2), round(x['median_ms']['gpu_sum'],3)) for x in v], v[0].get('hausdorff'), v[0].get('agree'))
PY
