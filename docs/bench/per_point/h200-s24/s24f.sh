#!/usr/bin/env bash
# Session 24, call 6 (one H200, 16 cores): the GPU tests on the session's
# last build, with the validation layer on rt-pipeline: the engine's suites
# the session touched (NarrowedTargets with the GPU's stray rule,
# ExactPerPoint, DeviceInput, PreparedSet, CallOptions, OutOfCore,
# SeveralDevices), rthdist_gpu_tests (the oracle suites) and the GPU
# surface tests.
BUNDLE=.devt
source tools/bench/device_prelude.sh
T=.devt/tests
export VK_LAYER_PATH=$PWD/.devt/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 250 $T/rthdist_engine_tests --gtest_filter='NarrowedTargets.*:ExactPerPoint.*:DeviceInput.*:PreparedSet.*:CallOptions.*:OutOfCore.*:SeveralDevices.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/engine_tests.txt | tr '\n' ' ')"
timeout 200 $T/rthdist_gpu_tests > $RES/gpu_tests.txt 2>&1; echo "gpu tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/gpu_tests.txt | tr '\n' ' ')"
timeout 120 $T/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "gpu surface tests exit $? $(grep -E '^\[  (PASSED|FAILED)|SKIPPED' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
grep -h -c "validation:" $RES/*.txt
