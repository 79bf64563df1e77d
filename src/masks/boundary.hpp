// Voxel selection and boundary extraction on the CPU (multithreaded over
// z-slabs). Internal to rthdist_masks; the GPU version is shaders/masks/.
//
// Boundary under connectivity c (6, 18, 26): a foreground voxel with at least
// one of its c neighbours in the background or outside the volume (the
// volume's outside counts as background, as SciPy's binary_erosion with
// border_value=0 does). Equals mask AND NOT erosion(mask, c-structure).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "masks/masks.hpp"

namespace rthdist::masks::detail {

using Dims = std::array<int64_t, 3>;

// A selected mask: 1 where the volume's label matches, else 0, with the
// number of set voxels and their bounding box [lo, hi) (lo = hi = 0 when none).
struct Selection {
    std::vector<uint8_t> mask;
    uint64_t count = 0;
    Dims lo{0, 0, 0}, hi{0, 0, 0};
};

[[nodiscard]] Selection selectMask(const Volume& v, LabelSelect select, int threads);

// Ascending linear indices of the boundary voxels of `s` (scans its box only).
[[nodiscard]] std::vector<uint64_t> boundaryVoxels(const Selection& s, Dims dims, int connectivity,
                                                   int threads);

// Ascending linear indices of voxels set in `s` and not in `other`.
[[nodiscard]] std::vector<uint64_t> differenceVoxels(const Selection& s, const Selection& other, Dims dims,
                                                     int threads);

[[nodiscard]] inline std::array<int64_t, 3> voxelOf(uint64_t linear, Dims dims) {
    const int64_t i = int64_t(linear % uint64_t(dims[0]));
    const uint64_t rest = linear / uint64_t(dims[0]);
    return {i, int64_t(rest % uint64_t(dims[1])), int64_t(rest / uint64_t(dims[1]))};
}

}  // namespace rthdist::masks::detail
