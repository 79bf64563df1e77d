#!/usr/bin/env bash
# Session 17, call 6: device-ingest pairs past 2^22 points look for
# narrowing too (from the device's bounds): cluster-5M before (78f4947) and
# after, --verify'd, CuPy's KDTree beside it; then the scale suite (PROCS=2,
# --verify) on the new build (cluster-100M now looks: its strays are their
# own, so it does not narrow and pays the look).
set -uo pipefail
B=.devs; W=/tmp/dw; here=tools/bench; mkdir -p $OUT $W /tmp/res
trap "cp $OUT/*.jsonl /tmp/res/ 2>/dev/null; tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
python3 - $here $W cluster-5M <<'PY'
import sys; sys.path.insert(0, sys.argv[1])
import density
for r in sys.argv[3:]: density.prepare(r, '/nonexistent', sys.argv[2])
PY
r=cluster-5M
$B/rthdist $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --verify --json --quiet > /tmp/res/verify_$r.json 2>&1
echo "verify $r exit $? $(python3 -c "import json,sys; d=json.load(open(sys.argv[1])); v=d['verify']; print(d['hausdorff'], v['ok'], v['max_abs_diff'], d['counters']['a_to_b']['narrowed_targets'])" /tmp/res/verify_$r.json 2>&1 | head -c 200)"
$B/rthdist-bench-before $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 2 --warmup 1 --no-verify 2>> $OUT/errors.txt |
  python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='before'; print(json.dumps(d))" >> $OUT/density.jsonl
for round in 1 2; do
  $B/rthdist-bench $W/${r}_a.ply $W/${r}_b.ply --backend rt-pipeline --name $r --runs 7 --warmup 3 --no-verify 2>> $OUT/errors.txt |
    python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='after'; d['round']=$round; print(json.dumps(d))" >> $OUT/density.jsonl
done
python3 $here/gpu_density_peers.py $W $r --runs 3 >> $OUT/cupy.jsonl 2>> $OUT/errors.txt
python3 - $OUT/density.jsonl $OUT/cupy.jsonl <<'PY'
import json,sys
for l in open(sys.argv[1]):
    d=json.loads(l); m=d['median_ms']; print(d['case'], d['build'], 'wall', round(m['wall'],2), 'gpu', round(m['gpu_sum'],3), 'upload', round(m['upload'],2), 'pieces', round(m['pieces'],2))
for l in open(sys.argv[2]): print(l.strip()[:200])
PY
PROCS=2 bash tools/bench/gpu_scale_suite.sh $B /tmp/res/suite > /tmp/res/suite.txt 2>&1
echo "suite exit $?"; cut -c1-400 /tmp/res/suite/lines.txt
