#include "algo/index_space.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cpu/parallel.hpp"

namespace rthdist::algo {

Bounds boundsOf(std::span<const glm::vec3> points) {
    Bounds b;
    if (points.empty()) return b;
    glm::vec3 lo = points[0], hi = points[0];
    for (const glm::vec3& p : points) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    b.lo = glm::dvec3(lo);
    b.hi = glm::dvec3(hi);
    return b;
}

GridSpec makeGrid(const Bounds& targetBounds, int bits) {
    GridSpec g;
    g.bits = std::clamp(bits, kMinBits, kMaxBits);
    g.cellsPerAxis = 1u << g.bits;
    g.origin = targetBounds.lo;
    glm::dvec3 ext = targetBounds.hi - targetBounds.lo;
    double longest = std::max({ext.x, ext.y, ext.z});
    g.cellSize = longest > 0.0 ? longest / double(g.cellsPerAxis) : 1.0;
    // Make sure the max face maps inside the grid even after rounding.
    return g;
}

double exactScale(double maxAbs) {
    if (!(maxAbs > 0.0) || (maxAbs >= 0x1p-40 && maxAbs <= 0x1p40)) return 1.0;
    int e = 0;
    std::frexp(maxAbs, &e);
    return std::ldexp(1.0, -e);
}

uint32_t mortonEncode(uint32_t x, uint32_t y, uint32_t z) {
    auto spread = [](uint32_t v) {
        v &= 0x3ffu;
        v = (v | (v << 16)) & 0x030000ffu;
        v = (v | (v << 8)) & 0x0300f00fu;
        v = (v | (v << 4)) & 0x030c30c3u;
        v = (v | (v << 2)) & 0x09249249u;
        return v;
    };
    return spread(x) | (spread(y) << 1) | (spread(z) << 2);
}

int chooseBits(std::span<const glm::vec3> targets, const Bounds& bounds, double targetPointsPerCell) {
    const size_t n = targets.size();
    if (n <= 1) return kMinBits;
    constexpr int kProbeBits = 10;
    GridSpec probe = makeGrid(bounds, kMaxBits);
    probe.bits = kProbeBits;
    probe.cellsPerAxis = 1u << kProbeBits;
    glm::dvec3 ext = bounds.hi - bounds.lo;
    double longest = std::max({ext.x, ext.y, ext.z});
    if (!(longest > 0.0)) return kMinBits;
    probe.cellSize = longest / double(probe.cellsPerAxis);

    // Strided sample; its distinct-cell counts per level are trustworthy while
    // the sample still puts several points in each cell.
    const size_t stride = std::max<size_t>(1, n / 32768);
    std::vector<uint32_t> keys;
    keys.reserve(n / stride + 1);
    for (size_t i = 0; i < n; i += stride) {
        const glm::vec3& p = targets[i];
        keys.push_back(mortonEncode(cellCoord(p.x, probe.origin.x, probe.cellSize, probe.cellsPerAxis),
                                    cellCoord(p.y, probe.origin.y, probe.cellSize, probe.cellsPerAxis),
                                    cellCoord(p.z, probe.origin.z, probe.cellSize, probe.cellsPerAxis)));
    }
    std::sort(keys.begin(), keys.end());
    const double sample = double(keys.size());
    double estimate = 1.0;  // occupied cells at the previous level
    double growth = 8.0;
    int chosen = kMinBits;
    for (int k = 1; k <= kMaxBits; ++k) {
        const int shift = 3 * (kProbeBits - k);
        size_t distinct = 0;
        uint32_t last = ~0u;
        for (uint32_t key : keys) {
            uint32_t c = key >> shift;
            if (c != last) {
                ++distinct;
                last = c;
            }
        }
        double occupied;
        if (sample / double(distinct) >= 8.0 || stride == 1) {
            occupied = double(distinct);
            if (k > 1) growth = std::clamp(occupied / estimate, 1.0, 8.0);
        } else {
            occupied = estimate * growth;  // sample too thin: extrapolate
        }
        estimate = occupied;
        if (double(n) / occupied >= targetPointsPerCell)
            chosen = k;
        else
            break;
    }
    return chosen;
}

constexpr size_t kMagnitudeChunk = size_t(1) << 16;  // points per work item

double largestMagnitude(std::span<const glm::vec3> points) {
    const int threads = cpu::resolveThreads(0, points.size() / kMagnitudeChunk + 1);
    std::vector<float> part(size_t(threads), 0.0f);
    cpu::parallelChunks(points.size(), kMagnitudeChunk, threads, [&](size_t begin, size_t end, int t) {
        float v = part[size_t(t)];
        for (size_t i = begin; i < end; ++i)
            v = std::max({v, std::abs(points[i].x), std::abs(points[i].y), std::abs(points[i].z)});
        part[size_t(t)] = v;
    });
    return double(*std::max_element(part.begin(), part.end()));
}

}  // namespace rthdist::algo
