// Directions and their numbers (directions.hpp). Percentiles and counts come
// from selection, not sorting (order_statistics.hpp).
#include "masks/directions.hpp"

#include <algorithm>
#include <limits>

#include "core/timings.hpp"
#include "masks/order_statistics.hpp"
#include "masks/per_point_call.hpp"

namespace rthdist::masks::detail {
namespace {

glm::dvec3 worldOf(const Volume& v, std::array<int64_t, 3> ijk) {
    return glm::dvec3(v.voxelToWorld * glm::dvec4(double(ijk[0]), double(ijk[1]), double(ijk[2]), 1.0));
}

// The mean and world points of a filled direction on X's grid `v`.
void finishDirection(const Volume& v, Direction& d) {
    d.out.point = worldOf(v, d.out.voxel);
    d.out.nearestPoint = worldOf(v, d.out.nearestVoxel);
    d.out.mean = d.out.points ? d.sum / double(d.out.points) : 0.0;
}

void emptyValues(Convention c, EmptyStatus s, MaskResult& r) {
    const bool both = s == EmptyStatus::kBothEmpty;
    switch (c) {
        case Convention::kRthdist: r.emptyHd = r.emptyHdPercentile = "undefined"; break;
        case Convention::kMonai:
            r.emptyHd = both ? "nan" : "inf";
            r.emptyHdPercentile = "nan";
            break;
        case Convention::kMedpy: r.emptyHd = r.emptyHdPercentile = "error"; break;
        case Convention::kPlastimatch: r.emptyHd = r.emptyHdPercentile = both ? "0" : "undefined"; break;
        case Convention::kItk: r.emptyHd = r.emptyHdPercentile = "undefined"; break;
        case Convention::kDeepmind: break;  // deepmind.cpp
    }
}

// HD, ASSD, MSD, surface overlaps and surface Dice from both directions.
void summarise(Direction& da, Direction& db, double tolerance, int threads, MaskResult& r) {
    r.hd = std::max(da.out.hd, db.out.hd);
    const double nAll = double(da.out.points + db.out.points);
    r.assd = (da.sum + db.sum) / nAll;
    r.msd = 0.5 * (da.out.mean + db.out.mean);
    uint64_t within = 0;
    for (Direction* d : {&da, &db}) {
        const uint64_t w = countAtMost(d->distances, tolerance, threads);
        d->out.surfaceOverlap = double(w) / double(d->out.points);
        within += w;
    }
    r.surfaceDice = double(within) / nAll;
}

// Percentile p of each direction and their combination, in convention c
// (pooled: both directions' distances merged, medpy only).
struct PercentilePair {
    double a = 0.0, b = 0.0, combined = 0.0;
};

PercentilePair percentilesOf(Convention c, Direction& da, Direction& db, std::span<double> pooled, double p,
                             int threads) {
    PercentilePair v;
    const ValueRange ra{{da.least, da.out.hd}}, rb{{db.least, db.out.hd}};
    switch (c) {
        case Convention::kRthdist:
            v.a = percentileNearestRank(da.distances, p, threads, ra);
            v.b = percentileNearestRank(db.distances, p, threads, rb);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMonai:
            v.a = percentileLinear(da.distances, p, threads, ra);
            v.b = percentileLinear(db.distances, p, threads, rb);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMedpy:
            v.a = percentileLinear(da.distances, p, threads, ra);
            v.b = percentileLinear(db.distances, p, threads, rb);
            v.combined =
                percentileLinear(pooled, p, threads,
                                 ValueRange{{std::min(da.least, db.least), std::max(da.out.hd, db.out.hd)}});
            break;
        case Convention::kPlastimatch:
            v.a = percentilePlastimatch(da.distances, p, threads, ra);
            v.b = percentilePlastimatch(db.distances, p, threads, rb);
            v.combined = 0.5 * (v.a + v.b);
            break;
        case Convention::kItk:
        case Convention::kDeepmind: break;
    }
    return v;
}

// Every requested HD-p, per direction and combined (not for itk).
void addPercentiles(Convention c, const std::vector<double>& percentiles, Direction& da, Direction& db,
                    int threads, MaskResult& r) {
    core::UninitVector<double> pooled;
    if (c == Convention::kMedpy) {
        pooled.reserve(da.distances.size() + db.distances.size());
        pooled.assign(da.distances.begin(), da.distances.end());
        pooled.insert(pooled.end(), db.distances.begin(), db.distances.end());
    }
    for (double p : percentiles) {
        const PercentilePair v = percentilesOf(c, da, db, pooled, p, threads);
        da.out.percentiles.push_back(v.a);
        db.out.percentiles.push_back(v.b);
        r.hdPercentile.push_back(v.combined);
    }
}

}  // namespace

double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// MONAI and plastimatch have no connectivity parameter (SciPy's default cross;
// plastimatch's face neighbours): 6 whatever is asked. rthdist and MedPy take one.
int connectivityOf(Convention c, int requested) {
    const bool configurable = c == Convention::kRthdist || c == Convention::kMedpy;
    return configurable && requested != 0 ? requested : 6;
}

std::optional<Error> checkOptions(const MaskOptions& options) {
    if (options.connectivity != 0 && options.connectivity != 6 && options.connectivity != 18 &&
        options.connectivity != 26)
        return Error{ErrorCode::kInvalidArgument, "masks: connectivity must be 6, 18 or 26"};
    for (double p : options.percentiles)
        if (!(p >= 0.0 && p <= 100.0))
            return Error{ErrorCode::kInvalidArgument, "masks: percentile outside [0, 100]"};
    if (!(options.tolerance >= 0.0))
        return Error{ErrorCode::kInvalidArgument, "masks: tolerance must be >= 0"};
    return std::nullopt;
}

// The masks' calls run one after another, so their totals add up.
void addTimings(Timings& sum, const Timings& t) {
    core::addStageTimings(sum, t);
    sum.total += t.total;
}

Result<Direction> directionOf(const Volume& v, const VoxelMetric& metric, std::span<const uint64_t> queries,
                              const PerPoint& nearest, std::span<const uint64_t> targets, uint64_t zeros,
                              int threads) {
    if (queries.empty() || nearest.nearest.size() != queries.size())
        return Error{ErrorCode::kInternal, "masks: the engine returned no per-point nearest points"};
    RecomputedDirection r = recompute(metric, v.dims, queries, targets, nearest.nearest, threads);
    Direction d;
    d.out.points = queries.size() + zeros;
    d.out.hd = r.distances[r.witness];
    if (zeros == 0) {
        d.distances = std::move(r.distances);
    } else {
        d.distances.reserve(size_t(d.out.points));
        d.distances.assign(size_t(zeros), 0.0);
        d.distances.insert(d.distances.end(), r.distances.begin(), r.distances.end());
    }
    d.sum = r.sum;
    d.least = zeros == 0 ? r.least : 0.0;
    d.out.voxel = voxelOf(queries[r.witness], v.dims);
    d.out.nearestVoxel = voxelOf(targets[nearest.nearest[r.witness]], v.dims);
    finishDirection(v, d);
    return d;
}

NearestCall oneShotCall(Engine& engine, const VoxelMetric& metric, std::span<const uint64_t> targets,
                        int threads, MaskResult& timed) {
    return [&engine, &metric, targets, threads, &timed](std::span<const glm::vec3> q) {
        const auto t0 = Clock::now();
        const SearchPoints t = metric.searchPoints(targets, threads);
        timed.extractMs += msSince(t0);
        return engine.compute(PointView(q), PointView(t), perPointCall(true));
    };
}

Result<Direction> directed(const VoxelMetric& metric, const Volume& v, std::span<const uint64_t> queries,
                           uint64_t zeros, uint64_t zeroWitness, std::span<const uint64_t> targets,
                           const NearestCall& nearest, int threads, MaskResult& timed) {
    Result<Direction> d = Direction{};
    if (queries.empty()) {
        d->out.points = zeros;
        d->distances.assign(size_t(zeros), 0.0);
        d->out.hd = 0.0;
        d->out.voxel = d->out.nearestVoxel = voxelOf(zeroWitness, v.dims);
        finishDirection(v, *d);
        return d;
    }
    auto t0 = Clock::now();
    const SearchPoints q = metric.searchPoints(queries, threads);
    timed.extractMs += msSince(t0);
    t0 = Clock::now();
    Result<HausdorffResult> r = nearest(q);
    if (!r) return r.error();
    addTimings(timed.engine, r->timings);
    d = directionOf(v, metric, queries, r->aNearest, targets, zeros, threads);
    timed.distanceMs += msSince(t0);
    return d;
}

// A mask without points (na or nb is 0): which one, the convention's empty
// values, and NaN for every number.
void setEmpty(uint64_t na, uint64_t nb, size_t percentiles, MaskResult& r) {
    r.empty = na == 0 && nb == 0 ? EmptyStatus::kBothEmpty
              : na == 0          ? EmptyStatus::kAEmpty
                                 : EmptyStatus::kBEmpty;
    emptyValues(r.convention, r.empty, r);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    r.hd = r.assd = r.msd = r.surfaceDice = nan;
    r.hdPercentile.assign(percentiles, nan);
    r.aToB.hd = r.bToA.hd = r.aToB.mean = r.bToA.mean = nan;
    r.aToB.surfaceOverlap = r.bToA.surfaceOverlap = nan;
}

void combine(const MaskOptions& options, Direction& ab, Direction& ba, MaskResult& r) {
    summarise(ab, ba, options.tolerance, options.threads, r);
    if (options.convention == Convention::kItk) {
        r.assd = r.surfaceDice = ab.out.surfaceOverlap = ba.out.surfaceOverlap =
            std::numeric_limits<double>::quiet_NaN();
    } else {
        addPercentiles(options.convention, options.percentiles, ab, ba, options.threads, r);
    }
    r.aToB = std::move(ab.out);
    r.bToA = std::move(ba.out);
}

}  // namespace rthdist::masks::detail
