// Shared between C++ (src/masks_gpu) and GLSL (shaders/masks_gpu/boundary.comp):
// the push constants of the boundary pass. Buffers are reached through their
// device addresses, so the pass needs no descriptor sets.
#ifndef RTHDIST_MASKS_BOUNDARY_SHARED_H
#define RTHDIST_MASKS_BOUNDARY_SHARED_H

#ifdef __cplusplus
#include <cstdint>
namespace rthdist::masks_gpu::shared {
using uint = uint32_t;
#endif

// Workgroup size of the boundary dispatch (one invocation per 32 voxels).
#define RTHDIST_BOUNDARY_WG 64

// The box: nx * ny * nz voxels, x fastest (whole rows of the volume: x
// outside the box is outside the volume; rows outside it select nothing).
struct BoundaryPush {
    uint64_t labels;  // uint[]: 8-bit labels four to a word (voxel i in byte i & 3 of word i >> 2),
                      // or 32-bit labels one to a word
    uint64_t bits;    // uint[words]: bit (i & 31) of word (i >> 5) set when box voxel i is a boundary voxel
    uint nx, ny, nz;
    uint words;         // ceil(nx * ny * nz / 32)
    int value;          // the selected label (anyNonZero == 0)
    uint anyNonZero;    // 1: every non-zero label is selected
    uint eightBit;      // 1: 8-bit labels, 0: 32-bit
    uint maxL1;         // connectivity: 1 (6), 2 (18) or 3 (26) = the neighbours' largest |dx|+|dy|+|dz|
    uint wordStride;    // invocations in the dispatch: each takes words wordStride apart
};

#ifdef __cplusplus
}  // namespace rthdist::masks_gpu::shared
#endif

#endif
