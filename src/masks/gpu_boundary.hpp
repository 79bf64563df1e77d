// Boundary extraction with the compute pass of masks_gpu (boundary_pass.hpp):
// the same voxels as extractBoundary (boundary.hpp), in the same ascending
// order. Internal to rthdist_masks.
//
// The host's part: one pass over the volume that counts the selected voxels
// of each row (the vectorized count of the host extraction) and finds the box
// of whole rows holding them (rows outside it select nothing, so they are
// background to the pass); the box's rows are copied into the pass's staging
// memory, one submission uploads and marks them, and the bitmask read back
// becomes linear indices. What the device saves the host is the neighbour
// tests of every selected voxel.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "masks/boundary.hpp"
#include "rthdist/result.hpp"

namespace rthdist::masks_gpu {
class BoundaryPass;
}

namespace rthdist::masks::detail {

// One mask: a volume and the label selected in it.
struct MaskRef {
    const Volume* volume = nullptr;
    LabelSelect select;
};

// The boundaries of several masks through one submission of the pass
// (extraction i is masks[i]'s). kOutOfMemory when a box does not fit the
// pass (more than 2^32 - 1 voxels, or the device's buffers): the caller
// extracts on the host instead.
[[nodiscard]] Result<std::vector<Extraction>> extractBoundariesOnDevice(masks_gpu::BoundaryPass& pass,
                                                                        std::span<const MaskRef> masks,
                                                                        int connectivity, int threads);
// One mask (as above).
[[nodiscard]] Result<Extraction> extractBoundaryOnDevice(masks_gpu::BoundaryPass& pass, const Volume& v,
                                                         LabelSelect select, int connectivity, int threads);

// The masks' boundaries through the pass (one submission) when there is one
// (`pass` not null), else, or when a box does not fit it, on the host
// (extractBoundary). `where` becomes "device" when the pass found them.
[[nodiscard]] Result<std::vector<Extraction>> extractBoundaries(masks_gpu::BoundaryPass* pass,
                                                                std::span<const MaskRef> masks,
                                                                int connectivity, int threads,
                                                                std::string& where);

}  // namespace rthdist::masks::detail
