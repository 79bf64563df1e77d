# Sourced at the top of a one-call script for the device tool (docs/gpu.md),
# in the repository root, where the tool has set OUT:
#   source tools/bench/device_prelude.sh
# It unpacks the carried Vulkan loader and libdeflate (.gl/*.deb; libdeflate
# only where the machine has none), points the loader at the
# NVIDIA driver, unpacks a carried validation layer ($BUNDLE/layers/*.xz,
# BUNDLE defaulting to .devs), makes RES (default /tmp/res) for the call's
# files and packs it into $OUT/res.tgz when the script exits (whatever its
# status), and prints the cards and the host's cores.
# GL_ROOT (default /): where the .debs are unpacked; another directory
# tries the prelude off the device machine (then no ldconfig).
set -uo pipefail
: "${OUT:?OUT: set by the device tool}"
RES=${RES:-/tmp/res}
mkdir -p "$OUT" "$RES"
trap 'tar czf "$OUT/res.tgz" -C "$(dirname "$RES")" "$(basename "$RES")"' EXIT
for deb in .gl/*.deb; do
  # libdeflate (rthdist's gzip reads): the machine's own where it has one.
  case $deb in */libdeflate0_*) if ldconfig -p 2> /dev/null | grep -q 'libdeflate\.so\.0 '; then continue; fi ;; esac
  dpkg -x "$deb" "${GL_ROOT:-/}" > /dev/null
done
if [ "${GL_ROOT:-/}" = / ]; then ldconfig; fi
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
for layer in "${BUNDLE:-.devs}"/layers/*.xz; do
  if [ -e "$layer" ] && [ ! -e "${layer%.xz}" ]; then xz -dk "$layer"; fi
done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2> /dev/null || echo "no nvidia-smi"
nproc
