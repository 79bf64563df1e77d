#version 460
// Boundary voxels of a label box (masks/boundary.hpp's definition): a
// selected voxel with at least one neighbour under the connectivity that is
// not selected or lies outside the box. One invocation writes one 32-bit word
// of the boundary bitmask (32 consecutive voxels), so no two invocations
// write the same word and the host reads the voxels back in ascending order.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference2 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "masks_gpu/boundary_shared.h"

layout(local_size_x = RTHDIST_BOUNDARY_WG) in;
layout(push_constant, scalar) uniform Push { BoundaryPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Labels { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Bits { uint v[]; };

bool selectedAt(Labels labels, uint i) {
    int label = pc.eightBit != 0 ? int((labels.v[i >> 2] >> ((i & 3u) * 8u)) & 0xffu) : int(labels.v[i]);
    return pc.anyNonZero != 0 ? label != 0 : label == pc.value;
}

// Voxel (x, y, z) of the box, false outside it.
bool selectedXyz(Labels labels, int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= int(pc.nx) || y >= int(pc.ny) || z >= int(pc.nz)) return false;
    return selectedAt(labels, (uint(z) * pc.ny + uint(y)) * pc.nx + uint(x));
}

bool isBoundary(Labels labels, uint i) {
    if (!selectedAt(labels, i)) return false;
    int x = int(i % pc.nx), r = int(i / pc.nx);
    int y = r % int(pc.ny), z = r / int(pc.ny);
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int l1 = abs(dx) + abs(dy) + abs(dz);
                if (l1 == 0 || l1 > int(pc.maxL1)) continue;
                if (!selectedXyz(labels, x + dx, y + dy, z + dz)) return true;
            }
    return false;
}

void main() {
    Labels labels = Labels(pc.labels);
    Bits bits = Bits(pc.bits);
    uint voxels = pc.nx * pc.ny * pc.nz;
    for (uint w = gl_GlobalInvocationID.x; w < pc.words; w += pc.wordStride) {
        uint word = 0u;
        uint first = w * 32u;
        uint count = min(32u, voxels - first);
        for (uint b = 0u; b < count; ++b)
            if (isBoundary(labels, first + b)) word |= 1u << b;
        bits.v[w] = word;
    }
}
