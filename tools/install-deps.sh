#!/usr/bin/env bash
# Installs what rthdist needs to build and test on Debian 12 (bookworm).
# Mesa's lavapipe gained VK_KHR_ray_query in 24.1; bookworm ships 22.3, so the
# Vulkan driver comes from bookworm-backports (25.0.x). Open MPI (openmpi-bin,
# libopenmpi-dev) builds rthdist-mpi and its tests (mpirun). Idempotent: packages
# already present are left alone. Needs root or sudo.
#   RTHDIST_BENCH_DEPS=1  also python3-scipy/numpy for tools/bench
#   RTHDIST_LINT_DEPS=1   also clang-format for .ci/run
#   RTHDIST_FUZZ_DEPS=1   also clang-14 and its libFuzzer and sanitizer runtimes (tools/fuzz/run.sh,
#                         the asan preset's compiler)
#   RTHDIST_MASKS_DEPS=0  skip the Python oracle of tests/masks (numpy, scipy, scikit-image,
#                         nibabel; on by default: ctest runs it)
#   RTHDIST_PYTHON_DEPS=0 skip the Python package's build and tests (pybind11, pytest, venv,
#                         pip; scikit-build-core from bookworm-backports; on by default:
#                         tools/test.sh builds the package and runs tests/python)
set -euo pipefail

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

BASE_PKGS=(cmake g++ make pkg-config libvulkan-dev glslang-tools libglm-dev
  libtinygltf-dev libgtest-dev libnanoflann-dev zlib1g-dev libdeflate-dev liblzf-dev vulkan-validationlayers
  vulkan-tools nlohmann-json3-dev libcli11-dev libstb-dev strace
  openmpi-bin libopenmpi-dev)
EXTRA_PKGS=()
if [ "${RTHDIST_MASKS_DEPS:-1}" = 1 ]; then
  EXTRA_PKGS+=(python3 python3-numpy python3-scipy python3-skimage python3-nibabel)
fi
BACKPORTS_PKGS=(mesa-vulkan-drivers)
if [ "${RTHDIST_PYTHON_DEPS:-1}" = 1 ]; then
  EXTRA_PKGS+=(python3 python3-dev python3-numpy python3-scipy python3-pybind11 pybind11-dev
    python3-pytest python3-venv python3-pip)
  BACKPORTS_PKGS+=(python3-scikit-build-core)
fi
if [ "${RTHDIST_BENCH_DEPS:-0}" = 1 ]; then
  EXTRA_PKGS+=(python3 python3-scipy python3-numpy)
fi
# RTHDIST_LINT_DEPS=1: the formatter .ci/run checks with (Debian 12: clang-format 14).
if [ "${RTHDIST_LINT_DEPS:-0}" = 1 ]; then
  EXTRA_PKGS+=(clang-format)
fi
if [ "${RTHDIST_FUZZ_DEPS:-0}" = 1 ]; then
  EXTRA_PKGS+=(clang-14 libclang-rt-14-dev)
fi

have_all() {
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || return 1
  done
}

mesa_ok() {
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [ -n "$v" ] && dpkg --compare-versions "$v" ge 24.1
}

if have_all "${BASE_PKGS[@]}" "${EXTRA_PKGS[@]}" "${BACKPORTS_PKGS[@]}" && mesa_ok; then
  exit 0
fi

export DEBIAN_FRONTEND=noninteractive
# The mirror for bookworm-backports is the one the machine's bookworm suite
# already uses (deb822 .sources or one-line .list): no host is named here.
debian_mirror() {
  local f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk '/^URIs:/ {u=$2} /^Suites:/ && / bookworm( |$)/ {print u; exit}' "$f"
  done
  cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
    awk '$1 == "deb" && $3 == "bookworm" {print $2}' || true
}
if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  mirror=$(debian_mirror | grep -v security | head -n 1 || true)
  [ -n "$mirror" ] || { echo "install-deps: no bookworm mirror in the apt sources to take bookworm-backports from" >&2; exit 1; }
  echo "deb $mirror bookworm-backports main" |
    $SUDO tee /etc/apt/sources.list.d/rthdist-backports.list >/dev/null
fi
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${BASE_PKGS[@]}" "${EXTRA_PKGS[@]}" >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends -t bookworm-backports \
  "${BACKPORTS_PKGS[@]}" >/dev/null
mesa_ok || { echo "install-deps: mesa-vulkan-drivers >= 24.1 is required (lavapipe ray queries)" >&2; exit 1; }
