#include "api/surface_certify.hpp"

#include <glm/vec3.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "core/stopwatch.hpp"
#include "cpu/surface_search.hpp"

namespace rthdist::api {
namespace {

constexpr size_t kChunk = 4096;

// The largest bound of one thread's chunks, the smallest index on a tie.
struct Largest {
    double bound = -1.0;
    uint64_t query = 0;
};

// U(q) of every query: the rule in double against its candidate (an upper
// bound of its nearest distance), infinite without one.
std::vector<double> upperBounds(const PointView& points, const MeshView& surface,
                                std::span<const uint32_t> candidate, int threads, Largest& largest) {
    std::vector<double> bound(points.count);
    const size_t triangles = surface.triangleCount();
    const int workers = core::resolveThreads(threads, (points.count + kChunk - 1) / kChunk);
    std::vector<Largest> each(static_cast<size_t>(workers));
    core::parallelChunks(points.count, kChunk, workers, [&](size_t begin, size_t end, int thread) {
        Largest& mine = each[size_t(thread)];
        for (size_t q = begin; q < end; ++q) {
            const uint32_t t = candidate[q];
            bound[q] = t < triangles ? core::closestOnTriangle(points.at(q), surface.corner(t, 0),
                                                               surface.corner(t, 1), surface.corner(t, 2))
                                           .distance2
                                     : std::numeric_limits<double>::infinity();
            if (bound[q] > mine.bound) mine = Largest{bound[q], q};
        }
    });
    for (const Largest& l : each) {
        if (l.bound > largest.bound || (l.bound == largest.bound && l.query < largest.query)) largest = l;
    }
    return bound;
}

// d(q)^2 by every triangle (the brute force's rule and order).
double exactNearest2(const glm::dvec3& p, const MeshView& surface) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t t = 0; t < surface.triangleCount(); ++t) {
        const double d2 =
            core::closestOnTriangle(p, surface.corner(t, 0), surface.corner(t, 1), surface.corner(t, 2))
                .distance2;
        if (d2 < best) best = d2;
    }
    return best;
}

}  // namespace

Result<SurfaceResult> certifySurface(const PointView& points, const MeshView& surface, double magnitude,
                                     std::span<const uint32_t> candidate, const SurfaceOptions& options) {
    if (options.perPointDistances)
        return Error{ErrorCode::kInvalidArgument,
                     "the proof of a surface search gives no per-point distances"};
    if (candidate.size() != points.count)
        return Error{ErrorCode::kInternal, "surface proof: " + std::to_string(candidate.size()) +
                                               " candidates for " + std::to_string(points.count) + " points"};
    Largest largest;
    const std::vector<double> bound = upperBounds(points, surface, candidate, options.threads, largest);
    const double lower2 = exactNearest2(points.at(largest.query), surface);  // L^2 <= h^2

    // The band, in index order: every query that may reach L.
    std::vector<glm::dvec3> band;
    std::vector<uint64_t> bandIndex;
    for (size_t q = 0; q < points.count; ++q) {
        if (bound[q] >= lower2) {
            band.push_back(points.at(q));
            bandIndex.push_back(q);
        }
    }
    Result<SurfaceResult> exact = cpu::surfaceSearch(PointView(band), surface, magnitude, options);
    if (!exact) return exact.error();
    SurfaceResult& r = exact.value();
    SurfaceDirected& d = r.directed;
    if (std::sqrt(lower2) > d.distance) {  // q* is in the band: never, unless a search is wrong
        return Error{ErrorCode::kInternal, "surface proof: the band's maximum " + std::to_string(d.distance) +
                                               " is below the measured query " +
                                               std::to_string(largest.query)};
    }
    d.queryIndex = bandIndex[d.queryIndex];
    d.counters.queries = points.count;
    d.counters.band = band.size();
    return exact;
}

}  // namespace rthdist::api
