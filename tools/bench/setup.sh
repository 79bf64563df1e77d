#!/usr/bin/env bash
# Installs the benchmark's peers and plotting from Debian 12 (bookworm), and
# rthdist's own build dependencies (tools/install-deps.sh: cmake, glslang,
# Mesa lavapipe from bookworm-backports, ...). Idempotent; needs root or sudo.
#   bash tools/bench/setup.sh
# All four peers exist in bookworm main (checked with apt-cache policy):
#   python3-scipy 1.10.1   directed_hausdorff, cKDTree
#   python3-open3d 0.16.1  PointCloud.compute_point_cloud_distance
#   pcl-tools 1.13.0       pcl_compute_hausdorff
#   python3-faiss 1.7.3    IndexFlatL2 (CPU build)
#   python3-matplotlib 3.6.3, python3-numpy 1.24.2
# The surface benchmark's peers (tools/bench/surface_peers.py, issue 34):
#   libcgal-dev 5.5.1      surface-cgal (header-only; GMP, MPFR, Boost headers)
#   meshlab 2020.09        meshlabserver's "Hausdorff Distance" filter; it
#   xvfb, xauth            needs an X server with GLX (xvfb-run): offscreen
#                          aborts ("GLEW initialization failed")
# The scripts run under Debian's interpreter, /usr/bin/python3 (a pyenv or
# venv python3 earlier on PATH does not see these packages).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
PKGS=(python3 python3-numpy python3-scipy python3-open3d pcl-tools python3-faiss python3-matplotlib
      libcgal-dev meshlab xvfb xauth)

RTHDIST_BENCH_DEPS=1 bash "$here/../install-deps.sh"
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
/usr/bin/python3 -c "import numpy, scipy, open3d, faiss, matplotlib" 
command -v pcl_compute_hausdorff >/dev/null
command -v meshlabserver xvfb-run >/dev/null
test -f /usr/include/CGAL/Polygon_mesh_processing/distance.h
echo "bench setup: ok"
