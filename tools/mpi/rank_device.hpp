// One GPU per rank: which Vulkan device a rank of rthdist-mpi uses when
// --device is not given. With several usable devices on a node (for `auto`:
// hardware ray-tracing devices; for ray-query/rt-pipeline: devices with that
// path), rank i of the node takes usable device i modulo their count; with
// one or none the library's default (first usable; `auto` on a software-only
// node: the CPU backend) is kept, so a one-GPU or CPU-only node behaves as
// rthdist does. Collective over `comm` (it splits it by node).
#pragma once

#include <mpi.h>

#include "rthdist/options.hpp"

namespace rthdist::cli {

// The device index to use: options.deviceIndex when set (>= 0) or the
// backend is the CPU, else as above (-1 = the library's default).
[[nodiscard]] int deviceForRank(MPI_Comm comm, const Options& options);

}  // namespace rthdist::cli
