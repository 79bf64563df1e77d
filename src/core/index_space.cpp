#include "core/index_space.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include "core/parallel.hpp"

namespace rthdist::core {

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

namespace {

constexpr size_t kSampleSize = 32768;

// The probe keys of the sample, in ascending order (LSD radix sort, three
// passes of 10 bits, the three digit counts taken in one pass: linear in the
// sample, where a comparison sort of 32k keys cost ~1.5 ms per set on the
// host path). A key's cell coordinates are (p - origin) * (cells / longest),
// clamped: a product where a quotient cost ~3x the time, and the same keys
// for every caller (the CPU backend, the host and device-ingest paths).
std::vector<uint32_t> sortedSampleKeys(std::span<const glm::vec3> sample, const BitProbe& probe) {
    constexpr uint32_t kDigits = 1u << kProbeBits;
    const auto coord = [&](float p, double origin) {
        const double c = (double(p) - origin) * probe.perLength;
        if (!(c > 0.0)) return 0u;
        return c >= double(kDigits) ? kDigits - 1 : uint32_t(c);
    };
    std::vector<uint32_t> keys(sample.size()), tmp(sample.size());
    std::vector<uint32_t> start(3 * (kDigits + 1), 0);
    for (size_t i = 0; i < sample.size(); ++i) {
        const glm::vec3& p = sample[i];
        const uint32_t key =
            mortonEncode(coord(p.x, probe.origin.x), coord(p.y, probe.origin.y), coord(p.z, probe.origin.z));
        keys[i] = key;
        for (uint32_t d = 0; d < 3; ++d)
            ++start[d * (kDigits + 1) + ((key >> (d * kProbeBits)) & (kDigits - 1)) + 1];
    }
    for (uint32_t d = 0; d < 3; ++d) {
        uint32_t* digitStart = start.data() + d * (kDigits + 1);
        for (uint32_t v = 0; v < kDigits; ++v) digitStart[v + 1] += digitStart[v];
        const uint32_t shift = d * kProbeBits;
        for (uint32_t key : keys) tmp[digitStart[(key >> shift) & (kDigits - 1)]++] = key;
        keys.swap(tmp);
    }
    return keys;
}

// distinct[k], k = 1..kMaxBits: how many different cells of level k (the
// top 3k bits of a probe key) the sorted keys fall in. Two neighbours in the
// order differ at level k exactly when their highest differing bit is at or
// above the level's shift, so one pass over the neighbours counts every level.
LevelCounts distinctCellsPerLevel(const std::vector<uint32_t>& sorted) {
    std::array<size_t, kMaxBits + 1> firstLevel{};  // neighbour pairs first differing at level k
    for (size_t i = 1; i < sorted.size(); ++i) {
        const uint32_t diff = sorted[i] ^ sorted[i - 1];
        if (diff == 0) continue;
        const int high = 31 - std::countl_zero(diff);
        const int k = kProbeBits - high / 3;  // smallest k with 3 (kProbeBits - k) <= high
        if (k <= kMaxBits) ++firstLevel[size_t(std::max(k, 1))];
    }
    LevelCounts distinct{};
    size_t running = sorted.empty() ? 0 : 1;
    for (int k = 1; k <= kMaxBits; ++k) {
        running += firstLevel[size_t(k)];
        distinct[size_t(k)] = running;
    }
    return distinct;
}

}  // namespace

size_t sampleStride(size_t n) { return std::max<size_t>(1, n / kSampleSize); }

bool bitProbeOf(const Bounds& bounds, size_t n, BitProbe& probe) {
    if (n <= 1) return false;
    const glm::dvec3 ext = bounds.hi - bounds.lo;
    const double longest = std::max({ext.x, ext.y, ext.z});
    if (!(longest > 0.0)) return false;
    probe.origin = bounds.lo;
    probe.perLength = 1.0 / (longest / double(1u << kProbeBits));
    return true;
}

int chooseBitsFromSample(std::span<const glm::vec3> sample, size_t n, const Bounds& bounds,
                         double targetPointsPerCell) {
    BitProbe probe;
    if (!bitProbeOf(bounds, n, probe)) return kMinBits;
    return chooseBitsFromCounts(distinctCellsPerLevel(sortedSampleKeys(sample, probe)), sample.size(), n,
                                targetPointsPerCell);
}

int chooseBitsFromCounts(const LevelCounts& distinct, size_t sampledPoints, size_t n,
                         double targetPointsPerCell) {
    // Its distinct-cell counts per level are trustworthy while the sample
    // still puts several points in each cell.
    const bool whole = sampleStride(n) == 1;
    const double sampled = double(sampledPoints);
    double estimate = 1.0;  // occupied cells at the previous level
    double growth = 8.0;
    int chosen = kMinBits;
    for (int k = 1; k <= kMaxBits; ++k) {
        double occupied;
        if (sampled / double(distinct[size_t(k)]) >= 8.0 || whole) {
            occupied = double(distinct[size_t(k)]);
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

int chooseBits(std::span<const glm::vec3> targets, const Bounds& bounds, double targetPointsPerCell) {
    const size_t stride = sampleStride(targets.size());
    std::vector<glm::vec3> sample;
    sample.reserve(targets.size() / stride + 1);
    for (size_t i = 0; i < targets.size(); i += stride) sample.push_back(targets[i]);
    return chooseBitsFromSample(sample, targets.size(), bounds, targetPointsPerCell);
}

constexpr size_t kMagnitudeChunk = size_t(1) << 16;  // points per work item

double largestMagnitude(const Bounds& box) {
    const glm::dvec3 m = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    return std::max({m.x, m.y, m.z});
}

double largestMagnitude(std::span<const glm::vec3> points, int threads) {
    threads = core::resolveThreads(threads, points.size() / kMagnitudeChunk + 1);
    std::vector<float> part(size_t(threads), 0.0f);
    core::parallelChunks(points.size(), kMagnitudeChunk, threads, [&](size_t begin, size_t end, int t) {
        float v = part[size_t(t)];
        for (size_t i = begin; i < end; ++i)
            v = std::max({v, std::abs(points[i].x), std::abs(points[i].y), std::abs(points[i].z)});
        part[size_t(t)] = v;
    });
    return double(*std::max_element(part.begin(), part.end()));
}

}  // namespace rthdist::core
