// Index space of RT-HDIST (Kim, Lee, Kim 2025, Sec. 4.1): a cubic grid over the
// target bounding volume, cell edge s = L / 2^k with L the longest side.
// Shared by the GPU and CPU backends so both assign cells by the same rules.
//
// Rules (design.md §2): cell of t = floor((t - o) / s), clamped to [0, 2^k - 1]
// per axis; o and s are computed in double on the host. When every target is
// the same point (L = 0) s is 1, so nothing divides by zero.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

// By its path from here: every target that includes this header finds it
// (the shaders' own include path is the library layers').
#include "../../shaders/shared/rthdist_morton.h"

namespace rthdist::core {

// Largest bit count with a dense cell table (2^(3k) entries) that we allow.
inline constexpr int kMaxBits = 8;
inline constexpr int kMinBits = 1;
// Auto bit count aims at about this many target points per occupied cell.
inline constexpr double kTargetPointsPerCell = 6.0;

struct Bounds {
    glm::dvec3 lo{0.0};
    glm::dvec3 hi{0.0};
};

// The smallest box holding both.
[[nodiscard]] inline Bounds unite(const Bounds& a, const Bounds& b) {
    return Bounds{glm::min(a.lo, b.lo), glm::max(a.hi, b.hi)};
}

struct GridSpec {
    glm::dvec3 origin{0.0};  // min corner of the target bounds
    double cellSize = 1.0;   // s = L / 2^bits (1 when L = 0)
    int bits = 1;
    uint32_t cellsPerAxis = 2;
};

[[nodiscard]] Bounds boundsOf(std::span<const glm::vec3> points);

// bits <= 0 selects the bit count from the data (chooseBits).
[[nodiscard]] GridSpec makeGrid(const Bounds& targetBounds, int bits);

// Picks k so that occupied cells hold about kTargetPointsPerCell points, from
// a strided sample's occupancy extrapolated to the full set (design.md §5).
[[nodiscard]] int chooseBits(std::span<const glm::vec3> targets, const Bounds& bounds,
                             double targetPointsPerCell = kTargetPointsPerCell);
// chooseBits samples every sampleStride(n)-th point (about 32k of them).
[[nodiscard]] size_t sampleStride(size_t n);
// The rule of chooseBits over a sample taken elsewhere (sample[j] = point
// j * sampleStride(n) of a set of n points): the same bit count as chooseBits
// on the whole set (device input reads back only the sample).
[[nodiscard]] int chooseBitsFromSample(std::span<const glm::vec3> sample, size_t n, const Bounds& bounds,
                                       double targetPointsPerCell = kTargetPointsPerCell);

// The rule in its two halves, for a probe counted elsewhere (the GPU
// backend's probe_levels.comp). The probe: every sampled point's cell of
// 2^kProbeBits per axis over the box's longest side, coordinate
// (p - origin) * perLength in double, clamped; none when the rule needs no
// sample (n <= 1 or a box of zero extent: kMinBits).
inline constexpr int kProbeBits = 10;
struct BitProbe {
    glm::dvec3 origin{0.0};
    double perLength = 0.0;
};
[[nodiscard]] bool bitProbeOf(const Bounds& bounds, size_t n, BitProbe& probe);
// distinct[k], k = 1..kMaxBits: the probe cells of level k (a key's top 3k
// bits) that the `sampled` points of the sample fall in.
using LevelCounts = std::array<size_t, kMaxBits + 1>;
[[nodiscard]] int chooseBitsFromCounts(const LevelCounts& distinct, size_t sampled, size_t n,
                                       double targetPointsPerCell = kTargetPointsPerCell);

// The one scaling rule of both backends (squared distances are float there):
// 1 when the largest coordinate magnitude maxAbs lies in [2^-40, 2^40] (then
// every squared difference of distinct coordinates near maxAbs is a normal
// float and none overflows); else the power of two 2^-e with maxAbs in
// [2^(e-1), 2^e), which brings maxAbs into [0.5, 1). Applied in double and
// rounded to float, every scaled coordinate is exact or flushes to zero only
// below 2^-126 * maxAbs-scale, far inside design.md §1's tolerance. Finite for
// every finite maxAbs, subnormals included; 1 for maxAbs = 0.
[[nodiscard]] double exactScale(double maxAbs);

// p * scale computed in double and rounded: exact for a power of two that
// keeps the product a normal float (exactScale), never inf or NaN. What every
// backend searches, and what the out-of-core pieces compare.
[[nodiscard]] inline glm::vec3 scaled(const glm::vec3& p, double scale) {
    return glm::vec3(glm::dvec3(p) * scale);
}

// The largest coordinate magnitude of a float set (the maxAbs of exactScale).
// threads: as EngineOptions::threads (0: every hardware thread).
[[nodiscard]] double largestMagnitude(std::span<const glm::vec3> points, int threads = 0);
// The same from a set's box (the extremes of |p| lie on its corners).
[[nodiscard]] double largestMagnitude(const Bounds& box);

// spreadBits (one axis of a Morton key) and mortonEncode (the low 10 bits
// of x, y, z interleaved, x in bit 0): shaders/shared/rthdist_morton.h, the
// definition the GLSL index uses too. Inline: the CPU backend computes one
// per point.
using shared::mortonEncode;
using shared::spreadBits;

// Cell coordinate of p on one axis, clamped to the grid.
[[nodiscard]] inline uint32_t cellCoord(double p, double origin, double cellSize, uint32_t cellsPerAxis) {
    double c = (p - origin) / cellSize;
    if (!(c > 0.0)) return 0;
    if (c >= double(cellsPerAxis)) return cellsPerAxis - 1;
    return uint32_t(c);
}

// The Morton key of p's cell in grid g (cellCoord on each axis).
[[nodiscard]] inline uint32_t cellKey(const glm::dvec3& p, const GridSpec& g) {
    return mortonEncode(cellCoord(p.x, g.origin.x, g.cellSize, g.cellsPerAxis),
                        cellCoord(p.y, g.origin.y, g.cellSize, g.cellsPerAxis),
                        cellCoord(p.z, g.origin.z, g.cellSize, g.cellsPerAxis));
}

}  // namespace rthdist::core
