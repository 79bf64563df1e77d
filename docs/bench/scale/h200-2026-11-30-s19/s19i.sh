#!/usr/bin/env bash
# Session 19, call 9 (kind nvidia-h200): tools/bench/device_prelude.sh on
# the device machine: the loader, the ICD and the validation layer it sets
# up, read back by `rthdist --list-devices` and a small validated run.
source tools/bench/device_prelude.sh
ls .devs/layers
.devs/rthdist --list-devices | tee $RES/devices.txt
VK_LAYER_PATH=$PWD/.devs/layers .devs/rthdist --validation --backend rt-pipeline --json --quiet \
  .devs/data/dragon_vrip.ply.gz .devs/data/dragon_vrip_res2.ply.gz > $RES/run.json; echo "run rc=$?"
python3 -c "import json; d=json.load(open('$RES/run.json')); print(d['hausdorff'], d.get('validation_messages'))"
