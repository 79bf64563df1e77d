// Voxel selection and boundary extraction on the CPU (multithreaded over
// z-slices), read straight from the label volume (no mask is materialized).
// Internal to rthdist_masks.
//
// Boundary under connectivity c (6, 18, 26): a selected voxel with at least
// one of its c neighbours not selected or outside the volume (the volume's
// outside counts as background, as SciPy's binary_erosion with
// border_value=0 does). Equals mask AND NOT erosion(mask, c-structure).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "masks/masks.hpp"

namespace rthdist::masks::detail {

using Dims = std::array<int64_t, 3>;

struct Extraction {
    uint64_t count = 0;              // selected voxels
    std::vector<uint64_t> boundary;  // ascending linear indices of the boundary voxels
};

// One pass over the volume: the selected voxels' count and boundary.
[[nodiscard]] Extraction extractBoundary(const Volume& v, LabelSelect select, int connectivity, int threads);

// Ascending linear indices of voxels selected in `a` and not in `b` (same grid).
[[nodiscard]] std::vector<uint64_t> differenceVoxels(const Volume& a, LabelSelect sa, const Volume& b,
                                                     LabelSelect sb, int threads);

// The first voxel selected in both, if any.
[[nodiscard]] std::optional<uint64_t> firstCommonVoxel(const Volume& a, LabelSelect sa, const Volume& b,
                                                       LabelSelect sb);

[[nodiscard]] inline std::array<int64_t, 3> voxelOf(uint64_t linear, Dims dims) {
    const int64_t i = int64_t(linear % uint64_t(dims[0]));
    const uint64_t rest = linear / uint64_t(dims[0]);
    return {i, int64_t(rest % uint64_t(dims[1])), int64_t(rest / uint64_t(dims[1]))};
}

}  // namespace rthdist::masks::detail
