#!/usr/bin/env bash
# Session 21, call 9 (kind nvidia-h200: one H200, 16 cores): rthdist-masks
# on one pair under auto, which now takes the backend a one-shot call of
# the run's points would (the CPU for small masks), against the GPU (what
# auto took before: rt-pipeline on the H200) and the CPU named; the NIfTI
# samples of ../shared/data/nifti as nonzero masks, two pairs on one grid
# each (aal vs ch2bet, 181x217x181; HarvardOxford vs JHU, 182x218x182),
# 3 rounds.
source tools/bench/device_prelude.sh
B=.devs; N=$B/data/nifti
pairs=("$N/aal.nii.gz $N/ch2bet.nii.gz" "$N/HarvardOxford-cort-maxprob-thr0-1mm.nii.gz $N/JHU-WhiteMatter-labels-1mm.nii.gz")
timeout 60 $B/rthdist-masks --backend rt-pipeline --json ${pairs[0]} > /dev/null 2>&1  # the pipeline cache
for r in 1 2 3; do
  for p in 0 1; do
    for be in auto rt-pipeline cpu; do
      t0=$(date +%s%N)
      timeout 60 $B/rthdist-masks --backend $be --json ${pairs[$p]} > /tmp/m.json 2> /tmp/m.err
      rc=$?
      echo "pair $p $be rc $rc wall $(( ($(date +%s%N) - t0) / 1000000 )) ms $(python3 -c "
import json; d=json.load(open('/tmp/m.json')); r=d['results'][0]
print(d['backend'], 'hd', r['hd'], 'hd95', r['hd_percentile'], 'timings', r['timings_ms'])" 2>&1 | head -c 300)"
    done
  done
done
