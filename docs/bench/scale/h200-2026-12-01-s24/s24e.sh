#!/usr/bin/env bash
# Session 24, call 5 (one H200, 16 cores): the scale suite on the session's
# last build (the GPU backends' routes changed: pairs whose strays are their
# own run on the two cores; no GPU index, search, ingest or transfer code
# changed), PROCS=2, --verify: torus-300x400, crowded-20M, cluster-100M.
BUNDLE=.devt
source tools/bench/device_prelude.sh
PROCS=2 SCRATCH=/tmp/scale bash tools/bench/gpu_scale_suite.sh .devrun $RES/suite torus-300x400 crowded-20M cluster-100M
