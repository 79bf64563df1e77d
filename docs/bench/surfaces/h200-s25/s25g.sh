#!/usr/bin/env bash
# Session 25, call 7 (one H200, 16 cores): the session's last build's GPU
# tests on rt-pipeline with the validation layer: rthdist_gpu_tests, the
# GPU surface tests and the engine's device tests (auto routing changed:
# devices named or validation keep the Vulkan path).
BUNDLE=.devx
source tools/bench/device_prelude.sh
B=.devx
export VK_LAYER_PATH=$PWD/$B/layers RTHDIST_TEST_BACKEND=rt-pipeline
timeout 200 $B/rthdist_gpu_tests > $RES/gpu_tests.txt 2>&1; echo "gpu tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_tests.txt | tr '\n' ' ')"
timeout 150 $B/rthdist_gpu_surface_tests > $RES/gpu_surface_tests.txt 2>&1; echo "surface tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/gpu_surface_tests.txt | tr '\n' ' ')"
timeout 200 $B/rthdist_engine_tests --gtest_filter='NarrowedTargets.*:NarrowTargets.*:DeviceInput.*:ExactPerPoint.*:CallOptions.*' > $RES/engine_tests.txt 2>&1; echo "engine tests exit $? $(grep -E '^\[  (PASSED|FAILED|  SKIPPED)' $RES/engine_tests.txt | tr '\n' ' ')"
$B/rthdist --validation --json data/bunny.ply data/bunny_res2.ply 2>&1 | python3 -c "import json,sys; d=json.load(sys.stdin); print('auto --validation:', d['backend'], d['device'], d['validation_messages'])"
grep -il "validation error\|VUID" $RES/*.txt || echo "no validation message"
