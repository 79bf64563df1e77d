#!/usr/bin/env bash
# Session 21, call 1 (kind nvidia-h200-x2; one device unless said): (1) the
# Engine's setup, the pipelines made on several threads and several devices
# opened at once (after) against 340211b (before), the CLI on the Dragon
# pair, 5 rounds alternated after one warm-up process each (the pipeline
# cache filled), on one device and with --devices 0,1; (2) docs/bench/gpu.md's rows, rthdist-bench of
# 340211b (before) and of this build alternated, 2 rounds; (3) the scale
# suite on this build (sessions 19-20's host changes were not all run on the
# device), PROCS=2, --verify, and the torus under the quarter's budget.
source tools/bench/device_prelude.sh
B=.devs; D=$B/data
pair="$D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz"
setup() {  # label binary [options]
  local label=$1 bin=$2; shift 2
  RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $pair > $RES/setup/$label.json 2> $RES/setup/$label.trace
  echo "$label $(python3 -c "
import json,sys; t=json.load(open(sys.argv[1]))['timings_ms']; print('setup', round(t['setup'],1), 'total', round(t['total'],2), 'wall', round(t['wall'],1))" $RES/setup/$label.json) $(grep 'rthdist setup' $RES/setup/$label.trace | tr '\n' ' ' | cut -c1-300)"
}
mkdir -p $RES/setup
setup warm_before rthdist-before; setup warm_after rthdist
for r in 1 2 3 4 5; do setup before_$r rthdist-before; setup after_$r rthdist; done
for r in 1 2 3; do setup two_before_$r rthdist-before --devices 0,1; setup two_after_$r rthdist --devices 0,1; done
timeout 200 bash tools/bench/gpu_certificate_ab.sh $B $RES/rows 2 > $RES/rows.txt 2>&1
echo "rows exit $?"; tail -12 $RES/rows.txt
PROCS=2 timeout 300 bash tools/bench/gpu_scale_suite.sh $B $RES/suite > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-230 $RES/suite/lines.txt
PROCS=2 EXTRA="--memory-budget 22400" timeout 120 bash tools/bench/gpu_scale_suite.sh $B $RES/quarter torus-300x400 > $RES/quarter.txt 2>&1
echo "quarter exit $?"; cut -c1-230 $RES/quarter/lines.txt
