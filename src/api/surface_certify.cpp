#include "api/surface_certify.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
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

// A band whose queries times triangles is at most this is measured by the
// brute force itself (no BVH to build: the usual band of one query).
constexpr uint64_t kBruteWork = uint64_t(1) << 24;

// q's nearest triangle by the brute force's rule and order (the smallest
// index on a tie), on the worker pool: every triangle is measured but those
// whose box lies farther than sqrt(within2) + slack (within2: U(q), at least
// q's nearest squared distance; infinite: none is skipped). That skip is the
// CPU backend's BVH pruning (design.md §11: core::closestSlack exceeds every
// rounding of the rule and of the box distance), applied to each
// triangle's own box, so the nearest triangle and every triangle tied with
// it are measured.
struct Nearest {
    double distance2 = std::numeric_limits<double>::infinity();
    uint32_t triangle = UINT32_MAX;
    uint64_t tested = 0;  // triangles measured by the rule
};

double pruneBound2(double within2, double slack) {
    if (!std::isfinite(within2)) return std::numeric_limits<double>::infinity();
    const double bound = std::sqrt(within2) + slack;
    return bound * bound;
}

Nearest bruteNearest(const glm::dvec3& p, const MeshView& surface, int threads, double within2,
                     double slack) {
    const size_t triangles = surface.triangleCount();
    const double prune2 = pruneBound2(within2, slack);
    const int workers = core::resolveThreads(threads, (triangles + kChunk - 1) / kChunk);
    std::vector<Nearest> each(static_cast<size_t>(workers));
    core::parallelChunks(triangles, kChunk, workers, [&](size_t begin, size_t end, int thread) {
        Nearest& mine = each[size_t(thread)];
        for (size_t t = begin; t < end; ++t) {
            const glm::dvec3 a = surface.corner(t, 0), b = surface.corner(t, 1), c = surface.corner(t, 2);
            const glm::dvec3 lo = glm::min(glm::min(a, b), c), hi = glm::max(glm::max(a, b), c);
            const glm::dvec3 out = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
            if (glm::dot(out, out) > prune2) continue;
            const double d2 = core::closestOnTriangle(p, a, b, c).distance2;
            ++mine.tested;
            if (d2 < mine.distance2 || (d2 == mine.distance2 && t < mine.triangle)) {
                mine.distance2 = d2;
                mine.triangle = uint32_t(t);
            }
        }
    });
    Nearest best;
    uint64_t tested = 0;
    for (const Nearest& n : each) {
        tested += n.tested;
        if (n.distance2 < best.distance2 || (n.distance2 == best.distance2 && n.triangle < best.triangle))
            best = n;
    }
    best.tested = tested;
    return best;
}

// The band by the brute force: the largest nearest distance, the smallest
// query on a tie (the band is in index order). q*'s nearest (`known`, of
// query `knownQuery`) is measured already.
SurfaceResult bruteBand(const PointView& points, std::span<const uint64_t> band, const MeshView& surface,
                        std::span<const double> bound, double slack, int threads, uint64_t knownQuery,
                        const Nearest& known) {
    SurfaceResult r;
    Nearest top;
    uint64_t topQuery = 0, tested = 0;
    bool any = false;
    for (const uint64_t q : band) {
        const Nearest n =
            q == knownQuery ? known : bruteNearest(points.at(q), surface, threads, bound[q], slack);
        tested += n.tested;
        if (!any || n.distance2 > top.distance2) {
            top = n;
            topQuery = q;
            any = true;
        }
    }
    SurfaceDirected& d = r.directed;
    d.queryIndex = topQuery;
    d.triangle = top.triangle;
    d.queryPoint = points.at(topQuery);
    const core::TriangleClosest c =
        core::closestOnTriangle(d.queryPoint, surface.corner(top.triangle, 0),
                                surface.corner(top.triangle, 1), surface.corner(top.triangle, 2));
    d.surfacePoint = c.point;
    d.barycentric = c.barycentric;
    d.distance = std::sqrt(c.distance2);
    d.counters.trianglesTested = tested;
    r.hausdorff = d.distance;
    return r;
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
    const double slack = core::closestSlack(magnitude);
    const Nearest measured =
        bruteNearest(points.at(largest.query), surface, options.threads, largest.bound, slack);
    const double lower2 = measured.distance2;  // L^2 <= h^2

    // The band, in index order: every query that may reach L.
    std::vector<uint64_t> bandIndex;
    for (size_t q = 0; q < points.count; ++q) {
        if (bound[q] >= lower2) bandIndex.push_back(q);
    }
    Result<SurfaceResult> exact = SurfaceResult{};
    if (bandIndex.size() * surface.triangleCount() <= kBruteWork) {
        exact = bruteBand(points, bandIndex, surface, bound, slack, options.threads, largest.query, measured);
    } else {  // the CPU backend's BVH search over the band (its own witness check)
        std::vector<glm::dvec3> band;
        band.reserve(bandIndex.size());
        for (const uint64_t q : bandIndex) band.push_back(points.at(q));
        exact = cpu::surfaceSearch(PointView(band), surface, magnitude, options);
        if (exact) exact->directed.queryIndex = bandIndex[exact->directed.queryIndex];
    }
    if (!exact) return exact.error();
    SurfaceDirected& d = exact->directed;
    if (std::sqrt(lower2) > d.distance) {  // q* is in the band: never, unless a search is wrong
        return Error{ErrorCode::kInternal, "surface proof: the band's maximum " + std::to_string(d.distance) +
                                               " is below the measured query " +
                                               std::to_string(largest.query)};
    }
    d.counters.queries = points.count;
    d.counters.band = bandIndex.size();
    return exact;
}

}  // namespace rthdist::api
