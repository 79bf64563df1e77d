#!/usr/bin/env bash
# Session 20, call 8 (kind nvidia-h200, 16 cores): the index build's keys and
# scatter passes in spread order (rthdist) against the build before
# (rthdist-before, the trace marks): the one call and the torus quarter
# (--memory-budget 22400) alternated, 3 rounds, with the phases of the
# index builds; then the scale suite (PROCS=2, --verify) on the new build.
source tools/bench/device_prelude.sh
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); sync; cat $S/a.ply $S/b.ply > /dev/null
one() {  # label binary args...
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > $RES/$label.json 2> $RES/$label.trace
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'gpu index', round(g['index']), 'pieces', round(t.get('pieces',0)))" $RES/$label.json 2>&1 | head -c 200)"
  grep "between marks" $RES/$label.trace | awk '{print "device", $14, "keys", $21, "scatter", $23}' | head -4 | tr '\n' ' '; echo
  xz -9 $RES/$label.trace
}
for r in 1 2 3; do
  one call_before_$r rthdist-before
  one call_after_$r rthdist
  one q_before_$r rthdist-before --memory-budget 22400
  one q_after_$r rthdist --memory-budget 22400
done
rm -f $S/*.ply
PROCS=2 timeout 330 bash tools/bench/gpu_scale_suite.sh $B $RES/suite > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-150 $RES/suite/lines.txt
