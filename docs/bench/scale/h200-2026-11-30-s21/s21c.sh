#!/usr/bin/env bash
# Session 21, call 3 (kind nvidia-h200: one H200, 16 cores): the CLI one-shot
# under --backend auto with a small pair on the CPU backend (oneShotBackendFor:
# at most 2^17 points a host thread, the build measured; 2^18 kept) against 340211b's auto (the GPU), and
# both explicit backends beside them: docs/bench/gpu.md's row inputs and
# the scale suite's crowded sphere (20M + 20M), 3 rounds, one process each.
source tools/bench/device_prelude.sh
B=.devs; D=$B/data; S=/tmp/rthdist-samples; here=tools/bench; mkdir -p $S $RES/cli
source $here/gpu_rows.sh
source $here/scale_cases.sh
scale_specs crowded-20M && scale_files $B /tmp/rthdist-scale && cases+=("crowded-20M ${files[0]} ${files[1]}")
one() {  # label binary A B [options]
  local label=$1 bin=$2 a=$3 b=$4; shift 4
  timeout 120 $B/$bin --json --quiet "$@" $a $b > $RES/cli/$label.json 2> $RES/cli/$label.err
  echo "$label $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print(d['backend'], d['hausdorff'], 'load', round(t['load'],1), 'setup', round(t['setup'],1), 'total', round(t['total'],1), 'wall', round(t['wall'],1))" $RES/cli/$label.json 2>&1 | head -c 200)"
}
for c in "${cases[@]}"; do
  set -- $c; name=$1 a=$2 b=$3
  one ${name}_warm rthdist $a $b --backend rt-pipeline > /dev/null
  for r in 1 2 3; do
    one ${name}_before_auto_$r rthdist-before $a $b
    one ${name}_after_auto_$r rthdist $a $b
    one ${name}_cpu_$r rthdist $a $b --backend cpu
    one ${name}_gpu_$r rthdist $a $b --backend rt-pipeline
  done
done
