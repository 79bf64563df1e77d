#!/usr/bin/env bash
# Session 20, call 4 (kind nvidia-h200-x2, 32 cores; one device): the scale
# suite on the session's GPU change (4c38b9c, the chunked upload as packed
# floats): every default case, PROCS=2, --verify; then the torus under the
# quarter's budget (pieces in space), PROCS=2, --verify.
source tools/bench/device_prelude.sh
B=.devs
PROCS=2 timeout 420 bash tools/bench/gpu_scale_suite.sh $B $RES/suite > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-230 $RES/suite/lines.txt
PROCS=2 EXTRA="--memory-budget 22400" timeout 140 bash tools/bench/gpu_scale_suite.sh $B $RES/quarter torus-300x400 > $RES/quarter.txt 2>&1
echo "quarter exit $?"; cut -c1-230 $RES/quarter/lines.txt
