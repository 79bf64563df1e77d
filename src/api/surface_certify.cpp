#include "api/surface_certify.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "core/searched_tops.hpp"
#include "core/stopwatch.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/surface_search.hpp"

namespace rthdist::api {
namespace {

// The smallest chunk of the passes measuring the rule (~50 ns a pair).
constexpr size_t kMinChunk = 256;

// The largest bound of one thread's chunks, the smallest index on a tie.
struct Largest {
    double bound = -1.0;
    uint64_t query = 0;
};

// The rule in double between query q and triangle t: infinite for none.
double measure2(const PointView& points, const MeshView& surface, uint64_t q, uint32_t t) {
    if (t >= surface.triangleCount()) return std::numeric_limits<double>::infinity();
    return core::closestOnTriangle(points.at(q), surface.corner(t, 0), surface.corner(t, 1),
                                   surface.corner(t, 2))
        .distance2;
}

// U(q) of every query: the rule in double against its candidate (an upper
// bound of its nearest distance), infinite without one. `perPoint` (sized
// by the caller, may be null): also each query's entry from that measure
// (no triangle: an infinite distance and UINT32_MAX).
core::UninitVector<double> upperBounds(const PointView& points, const MeshView& surface,
                                       std::span<const uint32_t> candidate, int threads, Largest& largest,
                                       SurfacePerPoint* perPoint = nullptr) {
    core::UninitVector<double> bound(points.count);  // every element written below
    const size_t chunk = core::balancedChunk(points.count, threads, kMinChunk, 4096);
    const int workers = core::resolveThreads(threads, (points.count + chunk - 1) / chunk);
    std::vector<Largest> each(static_cast<size_t>(workers));
    const bool withPoints = perPoint != nullptr && !perPoint->closest.empty();
    core::parallelChunks(points.count, chunk, workers, [&](size_t begin, size_t end, int thread) {
        Largest& mine = each[size_t(thread)];
        for (size_t q = begin; q < end; ++q) {
            const uint32_t t = candidate[q];
            if (withPoints && t < surface.triangleCount()) {
                const core::TriangleClosest c = core::closestOnTriangle(
                    points.at(q), surface.corner(t, 0), surface.corner(t, 1), surface.corner(t, 2));
                bound[q] = c.distance2;
                perPoint->closest[q] = c.point;
                perPoint->barycentric[q] = c.barycentric;
            } else {
                bound[q] = measure2(points, surface, q, t);
                if (withPoints) perPoint->closest[q] = perPoint->barycentric[q] = glm::dvec3(0.0);
            }
            if (perPoint != nullptr) {
                perPoint->distance[q] = std::sqrt(bound[q]);
                perPoint->triangle[q] = t < surface.triangleCount() ? t : UINT32_MAX;
            }
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

// A query's nearest triangle by the brute force's rule and order (the
// smallest index on a tie).
struct Nearest {
    double distance2 = std::numeric_limits<double>::infinity();
    uint32_t triangle = UINT32_MAX;
    uint64_t tested = 0;  // triangles measured by the rule
    // Takes triangle t at d2 if nearer (ties: the smaller index).
    void offer(double d2, uint32_t t) {
        if (d2 < distance2 || (d2 == distance2 && t < triangle)) {
            distance2 = d2;
            triangle = t;
        }
    }
};

double pruneBound2(double within2, double slack) {
    if (!std::isfinite(within2)) return std::numeric_limits<double>::infinity();
    const double bound = std::sqrt(within2) + slack;
    return bound * bound;
}

// One query's brute force in one thread: the query, its pruning bound (the
// square of sqrt(b) + slack below) and its nearest so far.
struct Probe {
    glm::dvec3 p{0.0};
    double prune2 = std::numeric_limits<double>::infinity();
    Nearest best;

    // Triangle t (corners a, b, c; box lo-hi): skipped when its box lies
    // past the bound, else measured by the rule (and the bound tightened).
    void visit(size_t t, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& lo,
               const glm::dvec3& hi, double slack) {
        if (core::boxDistance2(p, lo, hi) > prune2) return;
        const double d2 = core::closestOnTriangle(p, a, b, c).distance2;
        ++best.tested;
        if (d2 < best.distance2) prune2 = std::min(prune2, pruneBound2(d2, slack));
        best.offer(d2, uint32_t(t));
    }
};

// Each query's nearest triangle (`queries`: indices into points) in one
// pass over the triangles on the worker pool: every triangle is measured
// but those whose box lies farther than sqrt(b) + slack, b the smaller of
// the query's within2 (at least its nearest squared distance: U(q), or
// infinite) and the nearest the thread has measured for it so far (a real
// triangle's: at least the nearest too). That skip is the CPU backend's
// BVH pruning (design.md §11: core::closestSlack exceeds every rounding of
// the rule and of the box distance), applied to each triangle's own box,
// so the nearest triangle and every triangle tied with it are measured.
std::vector<Nearest> bruteNearest(const PointView& points, std::span<const uint64_t> queries,
                                  const MeshView& surface, int threads, std::span<const double> within2,
                                  double slack) {
    const size_t k = queries.size(), triangles = surface.triangleCount();
    if (k == 0) return {};
    const size_t chunk = core::balancedChunk(triangles, threads, kMinChunk, 4096);
    const int workers = core::resolveThreads(threads, (triangles + chunk - 1) / chunk);
    std::vector<Probe> each(size_t(workers) * k);  // each thread's k probes
    for (size_t w = 0; w < size_t(workers); ++w) {
        for (size_t i = 0; i < k; ++i) {
            each[w * k + i].p = points.at(queries[i]);
            each[w * k + i].prune2 = pruneBound2(within2[i], slack);
        }
    }
    core::parallelChunks(triangles, chunk, workers, [&](size_t begin, size_t end, int thread) {
        Probe* mine = &each[size_t(thread) * k];
        auto pass = [&](Probe* probes, size_t count) {
            for (size_t t = begin; t < end; ++t) {
                const glm::dvec3 a = surface.corner(t, 0), b = surface.corner(t, 1), c = surface.corner(t, 2);
                const glm::dvec3 lo = glm::min(glm::min(a, b), c), hi = glm::max(glm::max(a, b), c);
                for (size_t i = 0; i < count; ++i) probes[i].visit(t, a, b, c, lo, hi, slack);
            }
        };
        if (k == 1) {  // the usual single query: its probe in registers
            Probe one = mine[0];
            pass(&one, 1);
            mine[0] = one;
        } else {
            pass(mine, k);
        }
    });
    std::vector<Nearest> best(k);
    for (size_t w = 0; w < size_t(workers); ++w) {
        for (size_t i = 0; i < k; ++i) {
            const Nearest& n = each[w * k + i].best;
            best[i].tested += n.tested;
            if (n.triangle != UINT32_MAX) best[i].offer(n.distance2, n.triangle);
        }
    }
    return best;
}

// Each query's nearest triangle: bruteNearest, or where a BVH over the
// triangles is given its query, one query a task (the same answer: the
// tree's query equals the brute force over every triangle, ties to the
// smaller index; `within2` is then not needed).
std::vector<Nearest> nearestOf(const PointView& points, std::span<const uint64_t> queries,
                               const MeshView& surface, int threads, std::span<const double> within2,
                               double slack, const cpu::TriangleBvh* tree) {
    if (tree == nullptr) return bruteNearest(points, queries, surface, threads, within2, slack);
    std::vector<Nearest> best(queries.size());
    core::parallelChunks(queries.size(), core::heavyItemChunk(queries.size(), threads), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t i = begin; i < end; ++i) {
                                 const cpu::NearestTriangle n = tree->nearest(points.at(queries[i]), slack);
                                 best[i].distance2 = n.distance2;
                                 best[i].triangle = n.triangle;
                                 best[i].tested = n.trianglesTested;
                             }
                         });
    return best;
}

// Queries measured exactly already (by bruteNearest), by query index.
using Known = std::vector<std::pair<uint64_t, Nearest>>;  // sorted by query

// Where q is, or would go, in `known`.
Known::const_iterator placeOf(const Known& known, uint64_t q) {
    return std::lower_bound(known.begin(), known.end(), q,
                            [](const Known::value_type& e, uint64_t v) { return e.first < v; });
}

const Nearest* knownOf(const Known& known, uint64_t q) {
    const auto it = placeOf(known, q);
    return it != known.end() && it->first == q ? &it->second : nullptr;
}

// The band by the brute force: the largest nearest distance, the smallest
// query on a tie (the band is in index order). The queries of `known` are
// measured already; the others in one pass over the triangles.
// trianglesTested: the rule's evaluations of that pass and of `known`.
SurfaceResult bruteBand(const PointView& points, std::span<const uint64_t> band, const MeshView& surface,
                        std::span<const double> bound, double slack, int threads, const Known& known,
                        const cpu::TriangleBvh* tree) {
    std::vector<uint64_t> rest;
    std::vector<double> restBound;
    for (const uint64_t q : band) {
        if (knownOf(known, q) == nullptr) {
            rest.push_back(q);
            restBound.push_back(bound[q]);
        }
    }
    const std::vector<Nearest> measured = nearestOf(points, rest, surface, threads, restBound, slack, tree);
    SurfaceResult r;
    Nearest top;
    uint64_t topQuery = 0, tested = 0;
    bool any = false;
    size_t next = 0;  // into rest and measured (both in band order)
    for (const Nearest& n : measured) tested += n.tested;
    for (const auto& [q, n] : known) tested += n.tested;
    for (const uint64_t q : band) {
        const Nearest* k = knownOf(known, q);
        const Nearest& n = k != nullptr ? *k : measured[next++];
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

// The band, in index order: every query whose U may reach L, found by the
// worker pool chunk by chunk and joined in chunk order (a function of its
// own: inlined in certifySurface, the serial loop ran 3x slower on 2 cores).
std::vector<uint64_t> bandOf(std::span<const double> bound, double lower2, int threads) {
    const size_t chunk = core::balancedChunk(bound.size(), threads);
    std::vector<std::vector<uint64_t>> parts((bound.size() + chunk - 1) / chunk);
    core::parallelChunks(bound.size(), chunk, threads, [&](size_t begin, size_t end, int) {
        std::vector<uint64_t>& mine = parts[begin / chunk];
        for (size_t q = begin; q < end; ++q) {
            if (bound[q] >= lower2) mine.push_back(q);
        }
    });
    return core::concatenateParts<std::vector<uint64_t>>(parts);
}

// The device's own distances (searched2: squared, in the search frame,
// where coordinates are (v - origin) * scale, |v'| <= 1) bound each U(q):
// |sqrt(U(q)) - sqrt(searched2[q]) / scale| <= kSearchedReach / scale.
// Why: the frame's rounding moves each float coordinate by at most 2^-25
// (a distance by at most 2 * sqrt(3) * 2^-25); the float rule's closest
// point lies within ~20 u_f of the float triangle (a convex combination or
// a clamped segment point, as in double: design.md §11, u_f = 2^-24) and
// its distance rounds by a few u_f (a division to 2.5 ulp); the double
// rule's own error is ~2^-40 of that. Together below 2^-18; 2^-16 leaves a
// factor 4. The bound is checked on a sample of each call (q* and
// kSearchedSamples queries spread over the indices): any sampled query
// outside it, or a distance that is not a number, and the proof measures
// every U(q) instead (upperBounds), trusting nothing of the device's.
constexpr size_t kSearchedSamples = 64;

// Where a query's U(q) may reach L (sqrt(lower2)): a query the device left
// without a candidate, measured on the host (open), or whose distance is
// not a number always may; else when its distance plus the reach is not
// below sqrt(L).
struct SearchedBound {
    std::span<const float> searched2;
    double scale = 1.0;
    double reach = 0.0;                             // kSearchedReach / scale
    [[nodiscard]] double upper(uint64_t q) const {  // an upper bound of sqrt(U(q)), or +inf
        const float d2 = searched2[q];
        if (!(d2 >= 0.0f) || std::isinf(d2)) return std::numeric_limits<double>::infinity();
        return std::sqrt(double(d2)) / scale + reach;
    }
    // Whether the device's distance of q agrees with U(q) = u2 within the
    // reach (the sample's check); true where it gives no bound (none, not a
    // number), which the proof never uses to skip a query.
    [[nodiscard]] bool agrees(uint64_t q, double u2) const {
        if (std::isinf(upper(q))) return true;
        return std::abs(std::sqrt(u2) - std::sqrt(double(searched2[q])) / scale) <= reach;
    }
};

// The device's distances by chunks (core::SearchedTops) in one pass of the
// worker pool, where the search did not summarize them. Since
// SearchedBound::upper grows with searchedKey's order, a chunk whose
// largest query's bound is below sqrt(L) holds no query of the band
// (bandBySearched skips it).
core::SearchedTops searchedTops(std::span<const float> searched2, int threads) {
    const size_t n = searched2.size();
    core::SearchedTops tops;
    tops.chunk = core::balancedChunk(n, threads);
    tops.top.resize((n + tops.chunk - 1) / tops.chunk);
    core::parallelChunks(n, tops.chunk, threads, [&](size_t begin, size_t end, int) {
        tops.top[begin / tops.chunk] = core::SearchedTops::topOf(searched2, begin, end);
    });
    return tops;
}

// The band from the device's distances: every query whose bound reaches
// sqrt(lower2) is measured (U(q) in double against its candidate, into
// `bound`), and kept where U(q) >= lower2; the others have U(q) < L
// (SearchedBound). Only the chunks of `tops` whose largest bound reaches
// sqrt(lower2), or that hold a query of `known`, are passed over. Index
// order, the worker pool chunk by chunk.
std::vector<uint64_t> bandBySearched(const PointView& points, const MeshView& surface,
                                     std::span<const uint32_t> candidate, const SearchedBound& searched,
                                     const core::SearchedTops& tops, const Known& known, double lower2,
                                     int threads, double* bound) {
    const double floor = std::sqrt(lower2);
    const size_t n = points.count, chunk = tops.chunk;
    std::vector<size_t> reached;  // the chunks passed over, in order
    for (size_t c = 0; c < tops.top.size(); ++c) {
        const auto k = placeOf(known, c * chunk);
        if (searched.upper(tops.top[c]) >= floor || (k != known.end() && k->first < (c + 1) * chunk))
            reached.push_back(c);
    }
    std::vector<std::vector<uint64_t>> parts(reached.size());
    core::parallelChunks(reached.size(), 1, threads, [&](size_t first, size_t last, int) {
        for (size_t i = first; i < last; ++i) {
            std::vector<uint64_t>& mine = parts[i];
            for (size_t q = reached[i] * chunk; q < std::min(n, (reached[i] + 1) * chunk); ++q) {
                if (searched.upper(q) < floor && knownOf(known, q) == nullptr) continue;
                bound[q] = measure2(points, surface, q, candidate[q]);
                if (bound[q] >= lower2) mine.push_back(q);
            }
        }
    });
    return core::concatenateParts<std::vector<uint64_t>>(parts);
}

}  // namespace

Result<SurfaceResult> certifySurface(const PointView& points, const MeshView& surface, double magnitude,
                                     std::span<const uint32_t> candidate, const SurfaceOptions& options,
                                     std::span<const uint32_t> open, std::span<const float> searched2,
                                     double searchScale, EveryQueryBound* every, const cpu::TriangleBvh* tree,
                                     const core::SearchedTops* searchedSummary) {
    if (options.perPointDistances)
        return Error{ErrorCode::kInvalidArgument,
                     "the proof of a surface search gives no per-point distances"};
    if (candidate.size() != points.count)
        return Error{ErrorCode::kInternal, "surface proof: " + std::to_string(candidate.size()) +
                                               " candidates for " + std::to_string(points.count) + " points"};
    const double slack = core::closestSlack(magnitude);
    const size_t triangles = surface.triangleCount();

    // The open queries first, exactly (their candidates' U as the first
    // bound); each then takes its nearest triangle for its candidate, so its
    // U below is its exact nearest distance.
    const core::Clock::time_point openStart = core::Clock::now();
    Known known;
    std::vector<uint32_t> settledCandidate;
    if (!open.empty()) {
        std::vector<uint64_t> openQueries;
        std::vector<double> within2;
        for (const uint32_t q : open) {
            if (q >= points.count || (!openQueries.empty() && q <= openQueries.back())) {
                return Error{ErrorCode::kInternal,
                             "surface proof: open query " + std::to_string(q) + " out of range or order"};
            }
            openQueries.push_back(q);
            within2.push_back(measure2(points, surface, q, candidate[q]));
        }
        const std::vector<Nearest> nearest =
            nearestOf(points, openQueries, surface, options.threads, within2, slack, tree);
        settledCandidate.assign(candidate.begin(), candidate.end());
        for (size_t i = 0; i < openQueries.size(); ++i) {
            known.emplace_back(openQueries[i], nearest[i]);
            settledCandidate[openQueries[i]] = nearest[i].triangle;
        }
        candidate = settledCandidate;
    }
    const double openMs = open.empty() ? 0.0 : core::msSince(openStart);

    // With the device's distances (and their sample agreeing), q* is the
    // query of the largest one and only the queries they do not rule out
    // are measured; else every U(q) is, q* the largest.
    // (The open queries' distances are their exact nearest ones now, in the
    // frame's units: q* is chosen among the queries by what is known of them.)
    std::vector<float> openAdjusted;
    if (!known.empty() && searched2.size() == points.count) {
        openAdjusted.assign(searched2.begin(), searched2.end());
        for (const auto& [q, n] : known) openAdjusted[q] = float(n.distance2 * searchScale * searchScale);
        searched2 = openAdjusted;
    }
    const SearchedBound searched{searched2, searchScale, kSearchedReach / searchScale};
    bool bySearched = every == nullptr && searched2.size() == points.count && searchScale > 0.0 &&
                      std::isfinite(searched.reach);
    Largest largest;
    core::UninitVector<double> bound;
    core::SearchedTops tops;
    if (bySearched) {
        bound = core::UninitVector<double>(points.count);  // written where measured
        // The search's summary serves where it covers the distances as given
        // (none of them adjusted for the open queries).
        if (known.empty() && searchedSummary != nullptr && searchedSummary->covers(points.count))
            tops = *searchedSummary;
        else
            tops = searchedTops(searched2, options.threads);
        const uint64_t top = tops.overall(searched2);
        largest = Largest{measure2(points, surface, top, candidate[top]), top};
        bound[top] = largest.bound;
        const uint64_t step = std::max<uint64_t>(1, points.count / kSearchedSamples);
        for (uint64_t q = 0; q < points.count && bySearched; q += step) {
            if (knownOf(known, q) != nullptr) continue;  // measured exactly already
            bySearched = searched.agrees(q, measure2(points, surface, q, candidate[q]));
        }
        if (knownOf(known, top) == nullptr) bySearched = bySearched && searched.agrees(top, largest.bound);
    }
    SurfacePerPoint* perPoint = every != nullptr ? every->perPoint : nullptr;
    if (perPoint != nullptr) {
        if (searched2.size() != points.count || !(searchScale > 0.0))
            return Error{ErrorCode::kInternal,
                         "surface proof: per-point entries need the device's distances"};
        cpu::sizePerPoint(*perPoint, points.count, !options.perPointDistancesOnly, options.threads);
        perPoint->tolerance = 2.0 * searched.reach;
    }
    if (!bySearched) {
        largest = Largest{};
        bound = upperBounds(points, surface, candidate, options.threads, largest, perPoint);
    }
    Nearest measured;  // q*'s nearest, exactly
    if (const Nearest* k = knownOf(known, largest.query)) {
        measured = *k;
    } else {
        const double within2[1] = {largest.bound};
        const uint64_t query[1] = {largest.query};
        measured = nearestOf(points, query, surface, options.threads, within2, slack, tree)[0];
        known.insert(placeOf(known, largest.query), {largest.query, measured});
    }
    const double lower2 = measured.distance2;  // L^2 <= h^2

    const std::vector<uint64_t> bandIndex = bySearched
                                                ? bandBySearched(points, surface, candidate, searched, tops,
                                                                 known, lower2, options.threads, bound.data())
                                                : bandOf(bound, lower2, options.threads);
    Result<SurfaceResult> exact = SurfaceResult{};
    if (tree != nullptr || bandIndex.size() * triangles <= kBruteWork) {
        exact = bruteBand(points, bandIndex, surface, bound, slack, options.threads, known, tree);
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
    exact->stages.tailHost = openMs;
    if (perPoint != nullptr) {
        // The witness's entry is the proven one.
        perPoint->distance[d.queryIndex] = d.distance;
        perPoint->triangle[d.queryIndex] = d.triangle;
        if (!perPoint->closest.empty()) {
            perPoint->closest[d.queryIndex] = d.surfacePoint;
            perPoint->barycentric[d.queryIndex] = d.barycentric;
        }
    }
    if (every != nullptr) {  // every U(q) measured (not bySearched)
        every->bound2 = std::move(bound);
        every->triangle.assign(candidate.begin(), candidate.end());
    }
    return exact;
}

bool perPointSamplesAgree(const PointView& points, const MeshView& surface, const SurfacePerPoint& entries,
                          double magnitude, int threads) {
    std::vector<uint64_t> samples;
    std::vector<double> within2;
    const uint64_t step = std::max<uint64_t>(1, points.count / kPerPointSamples);
    for (uint64_t q = 0; q < points.count && samples.size() < kPerPointSamples; q += step) {
        samples.push_back(q);
        within2.push_back(measure2(points, surface, q, entries.triangle[q]));
    }
    const std::vector<Nearest> exact =
        bruteNearest(points, samples, surface, threads, within2, core::closestSlack(magnitude));
    for (size_t i = 0; i < samples.size(); ++i) {
        const double d = entries.distance[samples[i]], nearest = std::sqrt(exact[i].distance2);
        if (!(d >= nearest && d - nearest <= entries.tolerance)) return false;
    }
    return true;
}

}  // namespace rthdist::api
