#!/usr/bin/env bash
# Session 24, call 7 (one H200, 16 cores): rthdist_gpu_tests with the
# validation layer on rt-pipeline on the last build (the sweep test's
# engines on the whole search, 9275be4), and the engine's NarrowedTargets.
BUNDLE=.devt
source tools/bench/device_prelude.sh
T=.devt/tests
export VK_LAYER_PATH=$PWD/.devt/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $T/rthdist_gpu_tests > $RES/gpu_tests.txt 2>&1; echo "gpu tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/gpu_tests.txt | tr '\n' ' ')"
timeout 120 $T/rthdist_engine_tests --gtest_filter='NarrowedTargets.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/engine_tests.txt | tr '\n' ' ')"
grep -h -c "validation:" $RES/*.txt
