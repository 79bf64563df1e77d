#include "cpu/surface_search.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "core/stopwatch.hpp"
#include "cpu/query_order.hpp"
#include "cpu/triangle_blocks.hpp"
#include "cpu/triangle_bvh.hpp"

namespace rthdist::cpu {
namespace {

// The maximum so far of one thread: the query with the largest distance,
// the smallest index on a tie.
struct ThreadBest {
    NearestTriangle hit;
    uint64_t query = 0;
    bool any = false;
    SurfaceCounters counters;
    bool cancelled = false;
};

bool beats(const NearestTriangle& hit, uint64_t query, const ThreadBest& best) {
    if (!best.any) return true;
    return hit.distance2 > best.hit.distance2 || (hit.distance2 == best.hit.distance2 && query < best.query);
}

// Non-negative doubles order as their bit patterns: the running maximum of
// squared distances is one atomic word.
void raiseMax(std::atomic<uint64_t>& bits, double value) {
    const uint64_t v = std::bit_cast<uint64_t>(value);
    uint64_t seen = bits.load(std::memory_order_relaxed);
    while (seen < v && !bits.compare_exchange_weak(seen, v, std::memory_order_relaxed)) {
    }
}

// The witness's nearest triangle by every triangle: chunks of the triangles
// on the worker pool, each in index order, joined by the smaller squared
// distance and then the smaller index, so the answer is the serial loop's
// (the first triangle at the smallest distance) on any thread count. A
// triangle whose box lies farther than (sqrt(within2) + slack)^2, within2
// the search's own answer, is not measured: the rounded box distance never
// exceeds a triangle's measure by the slack (design.md §11), so a triangle
// nearer than the search's answer, or tied with it, is always measured and
// a wrong answer is still caught. One thread measuring every triangle took
// ~20 ms of a 16-core call against the Dragon's 871k triangles. With
// `blocks` (a kept mesh's runs, cpu/triangle_blocks.hpp) a run whose box
// lies past that bound is skipped whole: none of its triangles would be
// measured (the same answer, without reading them).
NearestTriangle bruteNearest(const glm::dvec3& p, const MeshView& surface, double within2, double slack,
                             int threads, const TriangleBlocks* blocks) {
    constexpr size_t kTriangleChunk = size_t(1) << 14;  // a multiple of TriangleBlocks::kTriangles
    static_assert(kTriangleChunk % TriangleBlocks::kTriangles == 0);
    const double bound = std::sqrt(within2) + slack;
    const double bound2 = bound * bound;
    const size_t n = surface.triangleCount();
    const size_t chunks = (n + kTriangleChunk - 1) / kTriangleChunk;
    std::vector<NearestTriangle> each(chunks);
    core::parallelChunks(n, kTriangleChunk, threads, [&](size_t begin, size_t end, int) {
        NearestTriangle best;
        best.distance2 = std::numeric_limits<double>::infinity();
        const auto measure = [&](size_t from, size_t to) {
            for (size_t t = from; t < to; ++t) {
                const glm::dvec3 a = surface.corner(t, 0), b = surface.corner(t, 1), c = surface.corner(t, 2);
                if (core::boxDistance2(p, glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c)) > bound2)
                    continue;
                const core::TriangleClosest r = core::closestOnTriangle(p, a, b, c);
                if (r.distance2 < best.distance2) {
                    best.distance2 = r.distance2;
                    best.triangle = uint32_t(t);
                    best.point = r.point;
                }
            }
        };
        if (blocks == nullptr) {
            measure(begin, end);
        } else {
            constexpr size_t kRun = TriangleBlocks::kTriangles;
            for (size_t from = begin; from < end; from += kRun) {
                const size_t run = from / kRun;
                if (core::boxDistance2(p, blocks->lo(run), blocks->hi(run)) > bound2) continue;
                measure(from, std::min(end, from + kRun));
            }
        }
        each[begin / kTriangleChunk] = best;
    });
    NearestTriangle best;
    best.distance2 = std::numeric_limits<double>::infinity();
    for (const NearestTriangle& c : each) {  // chunk order = index order: strict < keeps the first
        if (c.distance2 < best.distance2) best = c;
    }
    return best;
}

}  // namespace

Result<SurfaceResult> surfaceSearch(const PointView& points, const MeshView& surface, double magnitude,
                                    const SurfaceOptions& options) {
    const core::Clock::time_point start = core::Clock::now();
    const TriangleBvh bvh(surface, options.threads);
    const double buildMs = core::msSince(start);
    Result<SurfaceResult> result = surfaceSearch(points, surface, magnitude, options, bvh);
    if (result) {
        result->buildMs = buildMs;
        result->totalMs = core::msSince(start);
    }
    return result;
}

void sizePerPoint(SurfacePerPoint& perPoint, size_t count, bool points, int threads) {
    if (!points) {  // (recycled arrays may hold a full call's)
        perPoint.closest.clear();
        perPoint.barycentric.clear();
    }
    core::parallelChunks(points ? 4 : 2, 1, threads, [&](size_t begin, size_t, int) {
        switch (begin) {
            case 0: perPoint.distance.resize(count); break;
            case 1: perPoint.triangle.resize(count); break;
            case 2: perPoint.closest.resize(count); break;
            default: perPoint.barycentric.resize(count); break;
        }
    });
}

Result<SurfaceResult> surfaceSearch(const PointView& points, const MeshView& surface, double magnitude,
                                    const SurfaceOptions& options, const TriangleBvh& bvh,
                                    const TriangleBlocks* blocks, SurfacePerPoint* spare) {
    const core::Clock::time_point start = core::Clock::now();
    SurfaceResult result;
    result.backend = Backend::kCpu;
    result.device = "cpu";

    const core::Clock::time_point searchStart = core::Clock::now();
    const double slack = core::closestSlack(magnitude);
    const bool perPoint = options.perPointDistances;
    const bool perPointClosest = perPoint && !options.perPointDistancesOnly;
    if (perPoint && spare != nullptr) result.perPoint = std::move(*spare);  // every element is written below
    if (perPoint) sizePerPoint(result.perPoint, points.count, perPointClosest, options.threads);
    const size_t chunk = core::heavyItemChunk(points.count, options.threads);
    const int threads = core::resolveThreads(options.threads, (points.count + chunk - 1) / chunk);
    // Queries near each other one after another (cpu/query_order.hpp): the
    // tree's nodes stay in cache; no answer depends on the order.
    const std::vector<uint32_t> order = perPoint || points.count <= kSpatialOrderEarlyBreakUpTo
                                            ? spatialOrder(points, options.threads)
                                            : std::vector<uint32_t>{};
    std::vector<ThreadBest> best(static_cast<size_t>(threads));
    std::atomic<uint64_t> runningMax{0};
    core::parallelChunks(points.count, chunk, threads, [&](size_t begin, size_t end, int thread) {
        ThreadBest& mine = best[size_t(thread)];
        if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
            mine.cancelled = true;
            return;
        }
        // The previous query's triangle first: consecutive queries are
        // neighbours, so it mostly dominates (early break) or bounds the
        // descent at once (per point).
        TriangleHint hint;
        for (size_t k = begin; k < end; ++k) {
            const size_t q = order.empty() ? k : order[k];
            const double stop =
                perPoint ? 0.0 : std::bit_cast<double>(runningMax.load(std::memory_order_relaxed));
            const NearestTriangle hit = bvh.nearest(points.at(q), slack, stop, hint);
            hint = {hit.position, hit.near};
            mine.counters.nodesVisited += hit.nodesVisited;
            mine.counters.trianglesTested += hit.trianglesTested;
            if (hit.dominated) {
                ++mine.counters.dominated;
                continue;
            }
            if (perPoint) {
                result.perPoint.distance[q] = std::sqrt(hit.distance2);
                result.perPoint.triangle[q] = hit.triangle;
                if (perPointClosest) {
                    result.perPoint.closest[q] = hit.point;
                    result.perPoint.barycentric[q] = hit.barycentric;
                }
            }
            if (beats(hit, q, mine)) {
                mine.hit = hit;
                mine.query = q;
                mine.any = true;
                raiseMax(runningMax, hit.distance2);
            }
        }
    });

    ThreadBest overall;
    SurfaceCounters& counters = result.directed.counters;
    for (const ThreadBest& b : best) {
        if (b.cancelled)
            return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceOptions::cancel)"};
        counters.nodesVisited += b.counters.nodesVisited;
        counters.trianglesTested += b.counters.trianglesTested;
        counters.dominated += b.counters.dominated;
        if (b.any && beats(b.hit, b.query, overall)) overall = b;
    }
    if (!overall.any) return Error{ErrorCode::kInternal, "surface search: no query was settled"};

    const glm::dvec3 q = points.at(overall.query);
    const NearestTriangle check =
        bruteNearest(q, surface, overall.hit.distance2, slack, options.threads, blocks);
    if (check.distance2 != overall.hit.distance2 || check.triangle != overall.hit.triangle) {
        return Error{ErrorCode::kInternal,
                     "surface search: the witness query " + std::to_string(overall.query) +
                         " found triangle " + std::to_string(overall.hit.triangle) + " at squared distance " +
                         std::to_string(overall.hit.distance2) + ", every triangle gives triangle " +
                         std::to_string(check.triangle) + " at " + std::to_string(check.distance2)};
    }
    SurfaceDirected& d = result.directed;
    d.distance = std::sqrt(overall.hit.distance2);
    d.queryIndex = overall.query;
    d.triangle = overall.hit.triangle;
    d.queryPoint = q;
    d.surfacePoint = overall.hit.point;
    d.barycentric = overall.hit.barycentric;
    counters.queries = points.count;
    counters.triangles = surface.triangleCount();
    counters.bvhNodes = bvh.nodeCount();
    result.hausdorff = d.distance;
    result.searchMs = core::msSince(searchStart);
    result.totalMs = core::msSince(start);
    return result;
}

}  // namespace rthdist::cpu
