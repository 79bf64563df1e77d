#!/usr/bin/env bash
# Session 29, call 7 (one H200, 16 cores), 90b6f7c's rthdist-surface-bench
# (sb-fq), kept rt-pipeline Engines, --runs 9 --warmup 2 --no-verify, 3
# rounds alternated:
#  A. the host's polling on the two rows short of 10x Open3D: the worker
#     pool's (RTHDIST_POOL_SPIN_US 0 / 50 / 200 = the default / 1000), the
#     fence's (RTHDIST_FENCE_SPIN_US 0), and 8 or 12 host threads of 16;
#  B. descent against the radii where 100k queries meet a mesh
#     (RTHDIST_SURFACE_DESCEND=1 against the rule: descent up to 65,536).
BUNDLE=.devx
source tools/bench/device_prelude.sh
cat /proc/loadavg
B=/tmp/b; mkdir -p $B; tar xJf .devx/m.tar.xz -C $B; M=$B/m
xz -dc .devx/sb-fq.xz > $B/sb; chmod +x $B/sb
one() {  # tag a b env... [-- args]
  local tag=$1 a=$2 b=$3; shift 3
  env "$@" timeout 60 $B/sb $M/$a.ply $M/$b.ply --backend rt-pipeline --runs 9 --warmup 2 --no-verify $EXTRA > $RES/$tag.json 2> $RES/$tag.err
}
for r in 1 2 3; do
  for row in bunny:bunny-res4 bunny:bunny-res3; do a=${row%%:*}; b=${row##*:}
    EXTRA= one "A-$a-$b-default-$r" $a $b
    EXTRA= one "A-$a-$b-pool0-$r" $a $b RTHDIST_POOL_SPIN_US=0
    EXTRA= one "A-$a-$b-pool50-$r" $a $b RTHDIST_POOL_SPIN_US=50
    EXTRA= one "A-$a-$b-pool1000-$r" $a $b RTHDIST_POOL_SPIN_US=1000
    EXTRA= one "A-$a-$b-fence0-$r" $a $b RTHDIST_FENCE_SPIN_US=0
    EXTRA="--threads 8" one "A-$a-$b-t8-$r" $a $b
    EXTRA="--threads 12" one "A-$a-$b-t12-$r" $a $b
  done
  for row in dragon-res2:dragon-res3 dragon-res2:dragon-res4 bunny:bunny-res2 bunny-res2:bunny-res3; do a=${row%%:*}; b=${row##*:}
    EXTRA= one "B-$a-$b-rule-$r" $a $b
    EXTRA= one "B-$a-$b-descend-$r" $a $b RTHDIST_SURFACE_DESCEND=1
  done
done
python3 - <<'PY'
import json, glob, statistics, collections, re
R = "/tmp/res"
groups = collections.defaultdict(list)
for f in sorted(glob.glob(f"{R}/*.json")):
    tag = re.sub(r"-\d+\.json$", "", f.split("/")[-1]); j = json.load(open(f)); k = j["kept_median_ms"]
    groups[tag].append((k["total"], k["gpu"], k["device"], k["upload"], k["readback"], k["certify"], j["hausdorff"], j["counters"]["radii"], j["counters"]["tail_queries"]))
for tag, v in groups.items():
    med = lambda i: statistics.median(x[i] for x in v)
    print(f"{tag:40s} totals " + " ".join("%.3f" % x[0] for x in v) + "  median %.3f gpu %.3f device %.3f upload %.3f readback %.3f certify %.3f H %s radii %d tail %d" % (med(0), med(1), med(2), med(3), med(4), med(5), v[0][6], v[0][7], v[0][8]))
PY
