#!/usr/bin/env bash
# The session-7 A/B of the surface search's tail on lavapipe (README.md of
# docs/bench/surfaces, "Few open queries on the host"): two builds of
# rthdist-surface-bench alternating, per process, row and backend.
#   BASE=path/to/old/rthdist-surface-bench NEW=path/to/new/rthdist-surface-bench \
#   INPUTS=dir/of/surface_inputs.py/files bash ab.sh OUT.jsonl PROCS ROW...
# ROW: name:points:mesh:runs (files INPUTS/points.ply, INPUTS/mesh.ply;
# runs timed calls after one warm-up call on one Engine). One JSON line
# per call of the tool: {"label": base|new, "proc", "be", "r": its output}.
set -uo pipefail
OUT=$1; PROCS=$2; shift 2
cd "${INPUTS:?}"
for p in $(seq 1 "$PROCS"); do
  for row in "$@"; do
    IFS=: read -r name pts mesh runs <<< "$row"
    for be in ray-query rt-pipeline; do
      for label in base new; do
        if [ "$label" = base ]; then bin=${BASE:?}; else bin=${NEW:?}; fi
        line=$("$bin" "$pts.ply" "$mesh.ply" --backend "$be" --runs "$runs" --warmup 1 --name "$name" \
          --no-verify 2>&1 | tail -1)
        echo "{\"label\":\"$label\",\"proc\":$p,\"be\":\"$be\",\"r\":$line}" >> "$OUT"
      done
    done
  done
done
