#!/usr/bin/env bash
# Session 25, call 4 (one H200, 16 cores): the scale suite after the BLAS
# builds' flag (PREFER_FAST_BUILD, src/gpu/accel.cpp) and the narrowing
# rule for frames below 2^-126, PROCS=2, --verify: torus-300x400,
# crowded-20M, cluster-100M, shell-400x400.
BUNDLE=.devx
source tools/bench/device_prelude.sh
PROCS=2 SCRATCH=/tmp/scale bash tools/bench/gpu_scale_suite.sh .devx $RES/suite torus-300x400 crowded-20M cluster-100M shell-400x400
