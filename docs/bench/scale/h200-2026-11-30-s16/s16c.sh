#!/usr/bin/env bash
# Session 16, last call: GPU tests with validation; docs/bench/gpu.md's rows and the small density rows,
# a0d8c75 (before) and HEAD (after) alternated; the torus one call's CLI before/after.
set -uo pipefail
B=.devp; D=$B/data; S=/tmp/rthdist-samples; W=/tmp/dw; here=tools/bench; mkdir -p $S $W $OUT /tmp/res
trap "cp $OUT/*.jsonl /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
VK_LAYER_PATH=$PWD/.devp/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 150 $B/rthdist_gpu_tests --gtest_filter='LargeSizes.*:*PerPointFloor*' > /tmp/res/gpu_tests.txt 2>&1; echo "gpu tests exit $?"; grep -E "^\[  (PASSED|FAILED)|tests ran" /tmp/res/gpu_tests.txt | head
# The small density rows (session 16's buffer fix), 2 rounds alternated.
rows="cluster-200k cluster-1M crowded-200k far-1mm-both"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for round in 1 2; do for build in before after; do
  bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
  for r in $rows; do
    $bin $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
      python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
  done
done; done
python3 - $OUT/density.jsonl <<'PY'
import json,sys,collections
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); rows[(d.get('name', d.get('case')),d['build'])].append(d)
for (n,b),v in sorted(rows.items()):
    print(n, b, [(round(x['median_ms']['wall'],2), round(x['median_ms']['gpu_sum'],3)) for x in v], v[0].get('hausdorff'))
PY
# docs/bench/gpu.md's rows, one-shot and per-point, 2 rounds alternated.
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
    print(n, 'per-point' if pp else 'one-shot', b, [(round(x['median_ms']['wall'],2), round(x['median_ms']['gpu_sum'],3)) for x in v], v[0].get('hausdorff'))
PY
# The torus one call through the CLI, before/after alternated (the engine created beside the load).
T=/tmp/rthdist-scale; mkdir -p $T
(./$B/rthdist-scale-gen torus 300000000 11 $T/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $T/b.ply & wait); cat $T/*.ply > /dev/null
for r in 1 2 3; do for v in rthdist-before rthdist; do
  $B/$v --json --quiet --backend rt-pipeline $T/a.ply $T/b.ply > /tmp/res/one_${v}_$r.json 2>/dev/null
  python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print(sys.argv[2], 'H', d['hausdorff'], 'wall', round(t['wall']), 'load', round(t['load']), 'setup', round(t['setup']), 'total', round(t['total']))" /tmp/res/one_${v}_$r.json "one $v $r"
done; done
