#!/usr/bin/env bash
# Session 21, call 8 (kind nvidia-h200): which of rthdist's device features
# makes a process's first vkCreateDevice slow (devprobe2.cpp, built as
# devprobe.cpp is in s21g.sh): the first device bare, with the Vulkan
# 1.2/1.3 features, + acceleration structures, or everything (+ the
# ray-tracing pipeline), then everything once more; 2 processes a variant,
# alternated.
source tools/bench/device_prelude.sh
for r in 1 2; do for v in bare v12 accel full; do timeout 60 .devs/devprobe2 $v; done; done
