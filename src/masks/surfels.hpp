// DeepMind surface-distance's surfels of a mask on the CPU (multithreaded
// over corner slices), read straight from the label volume. Internal to
// rthdist_masks.
//
// The surfel grid has (nx + 1) x (ny + 1) x (nz + 1) corners: corner (i, j, k)
// sits at voxel coordinates (i - 1/2, j - 1/2, k - 1/2), between voxels
// i - 1 and i on axis 0 (and so on); voxels outside the volume count as
// unselected. A corner is a surfel when its neighbour code (surfel_area.hpp)
// is neither 0 nor 255 — what DeepMind computes on its cropped, zero-padded
// copy with scipy.ndimage.correlate.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

struct Surfels {
    uint64_t selected = 0;          // selected voxels
    std::vector<uint64_t> corners;  // ascending linear corner indices: i + (nx + 1) * (j + (ny + 1) * k)
    std::vector<uint8_t> codes;     // the neighbour code of each
};

[[nodiscard]] Surfels extractSurfels(const Volume& v, LabelSelect select, int threads);

[[nodiscard]] inline std::array<int64_t, 3> cornerOf(uint64_t linear, std::array<int64_t, 3> voxelDims) {
    const uint64_t cx = uint64_t(voxelDims[0]) + 1, cy = uint64_t(voxelDims[1]) + 1;
    return {int64_t(linear % cx), int64_t(linear / cx % cy), int64_t(linear / cx / cy)};
}

}  // namespace rthdist::masks::detail
