#include "cpu/query_order.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/input_frame.hpp"
#include "core/parallel.hpp"
#include "cpu/key_sort.hpp"
#include "rthdist_morton.h"

namespace rthdist::cpu {
namespace {

// Whether the queries come in space order already (a mesh's vertices, a
// scan's lines, a sorted set): of 64 runs of 32 consecutive queries strided
// over the set, more than half span at most twice what a run of Morton
// order spans in a volume filled uniformly, (32 / n)^(1/3) of the set's
// extent (a quarter at most), where a run in no order spans most of it.
// ~2048 points read.
bool inSpaceOrder(const PointView& points, double extent) {
    constexpr uint64_t kRuns = 64, kRun = 32;
    const uint64_t stride = (points.count - kRun) / (kRuns - 1);
    const double span = extent * std::min(0.25, 2.0 * std::cbrt(double(kRun) / double(points.count)));
    uint64_t local = 0;
    for (uint64_t r = 0; r < kRuns; ++r) {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (uint64_t i = r * stride; i < r * stride + kRun; ++i) {
            lo = glm::min(lo, points.at(i));
            hi = glm::max(hi, points.at(i));
        }
        if (std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) <= span) ++local;
    }
    return local > kRuns / 2;
}

}  // namespace

std::vector<uint32_t> spatialOrder(const PointView& points, int threads) {
    const uint64_t n = points.count;
    if (n < kSpatialOrderFrom || n >= (uint64_t(1) << 32)) return {};
    // The queries' box by the input checks' own pass (they are checked: finite).
    const Result<core::SetSummary> summary = core::summarizeSet(points, "queries", threads);
    if (!summary) return {};
    const glm::dvec3 lo = summary->box.lo, hi = summary->box.hi;
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (inSpaceOrder(points, extent)) return {};
    const double toCell = extent > 0.0 ? 1023.0 / extent : 0.0;
    const size_t chunk = core::balancedChunk(n, threads);
    std::vector<uint64_t> keyed(n);
    core::parallelChunks(n, chunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t q = begin; q < end; ++q) {
            const glm::dvec3 c = (points.at(q) - lo) * toCell;  // in [0, 1023]
            const auto cell = [](double v) { return uint32_t(std::clamp(v, 0.0, 1023.0)); };
            const uint64_t key = shared::mortonEncode(cell(c.x), cell(c.y), cell(c.z));
            keyed[q] = key << 32 | uint64_t(q);
        }
    });
    radixSortKeys(keyed, 30, threads);
    std::vector<uint32_t> order(n);
    core::parallelChunks(n, chunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) order[i] = uint32_t(keyed[i]);
    });
    return order;
}

}  // namespace rthdist::cpu
