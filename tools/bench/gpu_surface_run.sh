#!/usr/bin/env bash
# The surface benchmark (issue 34; docs/bench/surfaces) on the lent GPU machine
# (Ubuntu 24.04, 16 cores, NVIDIA H200, python3 with numpy; no Open3D, no CGAL,
# no MeshLab, no network): every row of tools/bench/surface_peers.py with
# rthdist's cpu backend (16 threads) and, on the points rows, its rt-pipeline
# backend one-shot (the CLI: a device per call) and on a kept device
# (rthdist-surface-bench: one Engine, a warm-up call, then --runs calls of
# Engine::hausdorffToSurface), beside surface-cgal (CGAL 5.5: AABB_tree queries on 16 threads;
# bounded-error Hausdorff on one, as CGAL 5.5 has no parallel version of it).
# Ratios of the points rows are against rthdist-rt-pipeline-kept, of the surfaces
# rows against rthdist-cpu (--surface both runs on the cpu backend only);
# rthdist-cpu-1t (one thread) is shown beside CGAL's one-threaded call.
#   [PYTHON=python3] [RUNS=3] bash tools/bench/gpu_surface_run.sh BUNDLE OUTDIR [ROWS]
# ROWS: comma-separated row names of surface_peers.py (default: all).
# Writes OUTDIR/results.json, table.md, log.txt, machine.txt (GPU, cores,
# which libraries surface-cgal loaded).
#
# Assembling the bundle, here on Debian 12, in the repository root, after the
# release build (cmake --preset release && cmake --build build -j2):
#   echo /.devrun/ >> .git/info/exclude            # once; .gl/ as docs/gpu.md says
#   mkdir -p .devrun/surface/lib .devrun/surface/inputs
#   cp build/rthdist build/rthdist-surface-bench .devrun/surface/
#   # surface-cgal without CGAL's libraries there: CGAL is header-only; GMP and
#   # MPFR (Debian ships libgmp.a, libmpfr.a), libstdc++ and libgcc linked in
#   # statically; -frounding-math as CGAL's CMake adds it (interval filters).
#   g++ -std=c++17 -O2 -DNDEBUG -frounding-math -o .devrun/surface/surface-cgal \
#     tools/bench/surface_cgal.cpp -pthread -static-libstdc++ -static-libgcc \
#     -Wl,-Bstatic -lmpfr -lgmp -Wl,-Bdynamic
#   ldd .devrun/surface/surface-cgal   # libc and libm only; copy any other
#                                       # library it lists into .devrun/surface/lib/
#   /usr/bin/python3 tools/bench/surface_inputs.py ../shared/data .devrun/surface/inputs
#   # (the prepared PLY files, ~33 MB: the armadillo's decimation needs Open3D,
#   #  which the GPU machine lacks, so the inputs travel; with the repository
#   #  (~9 MB), the binaries (~6 MB) and .gl the call carries ~50 of its 64 MiB:
#   #  keep nothing else in the carried folders)
# and the Vulkan loader debs in .gl/ (docs/gpu.md). On the GPU machine, carry
# .gl and .devrun/surface (carry: [".gl", ".devrun/surface"]) and run from the
# repository root:
#   bash tools/bench/gpu_surface_run.sh .devrun/surface $OUT
# About 3-6 minutes of device time (the CGAL surfaces rows dominate).
# TOOLS overrides the peers and CPU columns (default rthdist-cpu,rthdist-cpu-1t,cgal);
# ONESHOT=rt-pipeline adds one-shot calls in one process (rthdist-rt-pipeline-oneshot).
# Open3D there: tools/bench/open3d_bundle.sh packs Debian 12's python3.11,
# numpy and python3-open3d with the libraries they load (not libc or
# libstdc++: the machine's newer ones serve) with a run.sh that sets
# LD_LIBRARY_PATH, PYTHONHOME and PYTHONPATH (~41 MB as tar.xz, carried in
# two calls: docs/bench/surfaces, sessions 10 and 22); then
# OPEN3D_PYTHON=that/run.sh (Open3D's worker only) and TOOLS=...,open3d.
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; ROWS=${3:-}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"

# The Vulkan loader (the machine has the NVIDIA driver but no loader).
if ! ldconfig -p | grep -q libvulkan.so.1 && [ -d .gl ]; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f "$nvidia_icd" ] && export VK_DRIVER_FILES=$nvidia_icd
export LD_LIBRARY_PATH=$B/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}

{
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
  echo "cores: $(nproc)"
  grep -m1 "model name" /proc/cpuinfo
  echo "surface-cgal libraries:"; ldd "$B/surface-cgal"
  "$B/rthdist" --list-devices
} > "$OUT/machine.txt" 2>&1

rows=()
[ -n "$ROWS" ] && rows=(--rows "$ROWS")
PYTHONUNBUFFERED=1 timeout 580 "${PYTHON:-python3}" "$here/surface_peers.py" --inputs "$B/inputs" --out "$OUT" \
  --rthdist "$B/rthdist" --cgal "$B/surface-cgal" --tools "${TOOLS:-rthdist-cpu,rthdist-cpu-1t,cgal}" \
  --gpu-backends rt-pipeline --surface-bench "$B/rthdist-surface-bench" --kept-backends rt-pipeline \
  --oneshot-backends "${ONESHOT:-}" --open3d-python "${OPEN3D_PYTHON:-}" \
  --reference rthdist-rt-pipeline-kept --runs "${RUNS:-3}" --cap 120 "${rows[@]}" 2>&1 | tee "$OUT/log.txt"
