// The Morton key of a cell, one definition for C++ (core/index_space.hpp:
// the CPU backend's keys and the probes) and GLSL (common.glsl: the GPU
// index's keys), so that both backends order cells alike. Plain functions
// of 32-bit unsigned integers, the subset both languages share.
#ifndef RTHDIST_MORTON_H
#define RTHDIST_MORTON_H

#ifdef __cplusplus
#include <cstdint>
namespace rthdist::shared {
using uint = uint32_t;
#define RTHDIST_MORTON_FN [[nodiscard]] constexpr inline
#else
#define RTHDIST_MORTON_FN
#endif

// The low 10 bits of v, two zero bits after each (one axis of a Morton key).
RTHDIST_MORTON_FN uint spreadBits(uint v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

// Interleaves the low 10 bits of x, y, z (x in bit 0): 30 bits.
RTHDIST_MORTON_FN uint mortonEncode(uint x, uint y, uint z) {
    return spreadBits(x) | (spreadBits(y) << 1) | (spreadBits(z) << 2);
}

#undef RTHDIST_MORTON_FN
#ifdef __cplusplus
static_assert(mortonEncode(1u, 0u, 0u) == 1u && mortonEncode(0u, 1u, 0u) == 2u &&
              mortonEncode(0u, 0u, 1u) == 4u && mortonEncode(0x3ffu, 0x3ffu, 0x3ffu) == 0x3fffffffu);
}  // namespace rthdist::shared
#endif
#endif
