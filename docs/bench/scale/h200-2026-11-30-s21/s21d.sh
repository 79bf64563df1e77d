#!/usr/bin/env bash
# Session 21, call 4 (one H200): the GPU tests and the engine's several-
# device and out-of-core tests on rt-pipeline with the Khronos validation
# layer (every message a failure), on the build whose pipelines are made on
# several host threads (6feecd0).
source tools/bench/device_prelude.sh
B=.devs
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 330 $B/rthdist_gpu_tests > $RES/gpu_tests.txt 2>&1; echo "gpu tests exit $?"
grep -E "^\[  (PASSED|FAILED) |tests ran|backend" $RES/gpu_tests.txt | tail -5
timeout 200 $B/rthdist_engine_tests --gtest_filter='SeveralDevices.*:OutOfCore.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $?"
grep -E "^\[  (PASSED|FAILED) |tests ran" $RES/engine_tests.txt | tail -5
