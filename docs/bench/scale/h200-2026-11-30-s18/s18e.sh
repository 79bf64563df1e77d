#!/usr/bin/env bash
# Session 18, call 5: 30091d3 against ebccadc again on the far rows, 5
# rounds (call 4's far-1mm-one, whose path the change does not alter, came
# out 0.3-0.5 ms slower in each of 3 rounds); the narrowing tests of the
# engine on rt-pipeline with the validation layer.
set -uo pipefail
B=.devs; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W /tmp/res
trap "cp $OUT/*.jsonl $OUT/*.txt /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dk $B/layers/libVkLayer_khronos_validation.so.xz
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline RTHDIST_VALIDATION=1 timeout 200 $B/rthdist_engine_tests \
  --gtest_filter='Narrow*' > /tmp/res/engine_narrow_tests.txt 2>&1
echo "engine narrowing tests exit $?"; grep -E "^\[  (PASSED|FAILED)|FAILED  \]" /tmp/res/engine_narrow_tests.txt | head
rows="far-1mm-one far-1mm-both cluster-200k"
python3 - $here $W $rows <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
for round in 1 2 3 4 5; do
  order="before after"; [ $((round % 2)) = 0 ] && order="after before"
  for build in $order; do
    bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
    for r in $rows; do
      $bin $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
    done
  done
done
python3 - $OUT/density.jsonl <<'PY'
import json,sys,collections
r=collections.defaultdict(list)
for l in open(sys.argv[1]):
    d=json.loads(l); m=d['median_ms']; r[(d['case'],d['build'])].append((round(m['wall'],2), round(m['upload'],2), round(m['pieces'],2)))
for (n,b),v in sorted(r.items()): print(n, b, 'wall/upload/narrowing', v)
PY
