#!/usr/bin/env bash
# Session 21, call 2 (kind nvidia-h200-x2; one device): call 1 ran out of
# time in a process that opened two devices at once (reverted); this build
# opens them one after the other and keeps the pipelines made on several
# threads. (1) docs/bench/gpu.md's rows, rthdist-bench of 340211b (before)
# and of this build alternated, 2 rounds; (2) the scale suite on this build,
# PROCS=2, --verify; (3) the torus under the quarter's budget, PROCS=2,
# --verify.
source tools/bench/device_prelude.sh
B=.devs
timeout 150 bash tools/bench/gpu_certificate_ab.sh $B $RES/rows 2 > $RES/rows.txt 2>&1
echo "rows exit $?"; tail -12 $RES/rows.txt
PROCS=2 timeout 330 bash tools/bench/gpu_scale_suite.sh $B $RES/suite > $RES/suite.txt 2>&1
echo "suite exit $?"; cut -c1-230 $RES/suite/lines.txt
PROCS=2 EXTRA="--memory-budget 22400" timeout 100 bash tools/bench/gpu_scale_suite.sh $B $RES/quarter torus-300x400 > $RES/quarter.txt 2>&1
echo "quarter exit $?"; cut -c1-230 $RES/quarter/lines.txt
