#!/usr/bin/env bash
# Session 21, call 6 (kind nvidia-h200-x2): how far a direction per device
# would take two GPUs on the torus 300M x 400M (issue 33's two-GPU goal),
# measured with today's CLI and no new code: (1) one process, both
# directions on device 0; (2) one process, h(A,B) alone on device 0, and
# h(B,A) alone; (3) the two directed processes at once, one per device
# (their wall: the later one's end). 3 rounds.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S $RES/dir
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
show() { python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print(sys.argv[1].split('/')[-1], 'H', d['hausdorff'], 'total', round(t['total']), 'upload', round(t['upload']), 'index', round(t['index']), 'cull', round(t['cull']), 'gpu', {k: round(v) for k, v in g.items() if v})" $1; }
run() {  # label device [args]
  local label=$1 dev=$2; shift 2
  timeout 120 $B/rthdist --json --quiet --backend rt-pipeline --device $dev "$@" > $RES/dir/$label.json 2> $RES/dir/$label.err
}
run warm 0 $S/a.ply $S/b.ply
for r in 1 2 3; do
  run both_$r 0 $S/a.ply $S/b.ply; show $RES/dir/both_$r.json
  run ab_$r 0 --directed $S/a.ply $S/b.ply; show $RES/dir/ab_$r.json
  run ba_$r 0 --directed $S/b.ply $S/a.ply; show $RES/dir/ba_$r.json
  t0=$(date +%s%N)
  run par_ab_$r 0 --directed $S/a.ply $S/b.ply & run par_ba_$r 1 --directed $S/b.ply $S/a.ply & wait
  echo "pair at once: $(( ($(date +%s%N) - t0) / 1000000 )) ms of wall for both processes"
  show $RES/dir/par_ab_$r.json; show $RES/dir/par_ba_$r.json
done
