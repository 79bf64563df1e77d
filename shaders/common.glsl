// Common declarations of rthdist's shaders: buffer references over device
// addresses, the Morton key, and the exact distance helpers. Distances are
// `precise` (no FMA contraction) and formed from raw float differences, so
// they match the host's double recomputation up to float rounding.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference2 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_scalar_block_layout : require

#include "rthdist_shared.h"

layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4Buf { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer UintBuf { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uvec2Buf { uvec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer U64Buf { uint64_t v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer CellBuf { Cell v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer StateBuf { QueryState v[]; };
layout(buffer_reference, scalar, buffer_reference_align = 4) buffer AabbBuf { float v[]; };

uint spreadBits(uint v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

uint mortonKey(uvec3 c) { return spreadBits(c.x) | (spreadBits(c.y) << 1) | (spreadBits(c.z) << 2); }

vec3 gridOrigin(GridParams g) { return vec3(g.originX, g.originY, g.originZ); }

// Unclamped integer cell coordinate of p (may lie outside the grid).
ivec3 cellOfUnclamped(vec3 p, GridParams g) {
    precise vec3 rel = (p - gridOrigin(g)) * g.invCellSize;
    return ivec3(floor(clamp(rel, vec3(-1.0e8), vec3(1.0e8))));
}

uvec3 cellOfClamped(vec3 p, GridParams g) {
    ivec3 c = cellOfUnclamped(p, g);
    return uvec3(clamp(c, ivec3(0), ivec3(int(g.cellsPerAxis) - 1)));
}

float dist2(vec3 a, vec3 b) {
    precise vec3 d = a - b;
    precise float r = d.x * d.x + d.y * d.y + d.z * d.z;
    return r;
}

// Squared Euclidean distance from q to the box [lo, hi] (0 inside).
float boxDist2(vec3 q, vec3 lo, vec3 hi) {
    precise vec3 d = max(max(lo - q, q - hi), vec3(0.0));
    precise float r = d.x * d.x + d.y * d.y + d.z * d.z;
    return r;
}

// Packed (squared distance, index) for 64-bit atomics; float bits of a
// non-negative float order like the float.
uint64_t packDistIndex(float d2, uint index) {
    return (uint64_t(floatBitsToUint(d2)) << 32) | uint64_t(index);
}
float packedDist2(uint64_t p) { return uintBitsToFloat(uint(p >> 32)); }

// The threshold below which a query cannot raise h: the larger of the exact
// running maximum (has a witness) and the witness-less lower bound.
// A negative lowerBound2 turns the early break off (per-point distances).
float deadThreshold(U64Buf maxPacked, float lowerBound2) {
    if (lowerBound2 < 0.0) return 0.0;
    uint64_t m = maxPacked.v[0];
    return max(packedDist2(m), lowerBound2);
}
