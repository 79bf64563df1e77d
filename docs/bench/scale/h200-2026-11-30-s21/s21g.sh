#!/usr/bin/env bash
# Session 21, call 7 (kind nvidia-h200-x2): where the driver's setup goes,
# with no rthdist code between: devprobe.cpp (built here: g++ -std=c++20
# -O1 -Iinclude -Ibuild/include devprobe.cpp -Wl,--start-group
# build/librthdist*.a -Wl,--end-group -lvulkan -lpthread -lz -ldeflate)
# times vkCreateInstance, the enumeration, and vkCreateDevice bare (one
# compute queue, nothing enabled) against rthdist's rt-pipeline set, 3
# rounds alternated in one process; three processes.
source tools/bench/device_prelude.sh
for p in 1 2 3; do echo "process $p"; timeout 60 .devs/devprobe; done
