// Directions and their numbers (directions.hpp). Percentiles and counts come
// from selection, not sorting (order_statistics.hpp).
#include "masks/directions.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "core/parallel.hpp"
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

// This direction's HD-p under the options' convention's rule (the
// area-weighted one is deepmind.cpp's; none: 0).
double directedPercentile(const MaskOptions& options, Direction& d, double p) {
    const ConventionRules& rules = conventionRules(options.convention);
    const ValueRange range{{d.least, d.out.hd}};
    const int threads = options.threads;
    if (p == 0.0 && rules.percentileAt0IsMax) return d.out.hd;  // MONAI: `if not percentile: return max`
    switch (rules.percentile) {
        case DirectedPercentile::kNearestRank: return percentileNearestRank(d.distances, p, threads, range);
        case DirectedPercentile::kTorchQuantile:
            return options.monaiFloat32 ? percentileTorchFloat32(d.distances, p, threads, range)
                                        : percentileLinear(d.distances, p, threads, range);
        case DirectedPercentile::kLinear: return percentileLinear(d.distances, p, threads, range);
        case DirectedPercentile::kKthSmallest: return percentilePlastimatch(d.distances, p, threads, range);
        case DirectedPercentile::kNone:
        case DirectedPercentile::kAreaWeighted: break;
    }
    return 0.0;
}

// HD, ASSD, MSD and surface Dice from both numbered directions.
void summarise(const Direction& da, const Direction& db, MaskResult& r) {
    r.hd = std::max(da.out.hd, db.out.hd);
    const double nAll = double(da.out.points + db.out.points);
    r.assd = (da.sum + db.sum) / nAll;
    r.msd = 0.5 * (da.out.mean + db.out.mean);
    r.surfaceDice = double(da.withinTolerance + db.withinTolerance) / nAll;
}

// Every requested HD-p combined from the directions' own (directionNumbers)
// by `how`: the larger, the mean, or (kPooled) the linear percentile of both
// directions' distances together.
void addPercentiles(Combination how, const std::vector<double>& percentiles, Direction& da, Direction& db,
                    int threads, MaskResult& r) {
    if (how == Combination::kNone) return;
    core::UninitVector<double> pooled;
    if (how == Combination::kPooled) {
        pooled.reserve(da.distances.size() + db.distances.size());
        pooled.assign(da.distances.begin(), da.distances.end());
        pooled.insert(pooled.end(), db.distances.begin(), db.distances.end());
    }
    const ValueRange both{{std::min(da.least, db.least), std::max(da.out.hd, db.out.hd)}};
    for (size_t i = 0; i < percentiles.size(); ++i) {
        const double a = da.out.percentiles[i], b = db.out.percentiles[i];
        r.hdPercentile.push_back(how == Combination::kPooled
                                     ? percentileLinear(pooled, percentiles[i], threads, both)
                                 : how == Combination::kMean ? 0.5 * (a + b)
                                                             : std::max(a, b));
    }
}

}  // namespace

// A convention without a connectivity parameter (MONAI: SciPy's default
// cross; plastimatch: face neighbours) measures 6 whatever is asked.
int connectivityOf(Convention c, int requested) {
    return conventionRules(c).connectivityOption && requested != 0 ? requested : 6;
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
                              std::span<const uint32_t> nearest, std::span<const uint64_t> targets,
                              uint64_t zeros, double tolerance, int threads) {
    if (queries.empty() || nearest.size() != queries.size())
        return Error{ErrorCode::kInternal, "masks: the engine returned no per-point nearest points"};
    RecomputedDirection r = recompute(metric, v.dims, queries, targets, nearest, tolerance, threads);
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
    d.withinTolerance = r.atMost + zeros;  // zeros are within any tolerance (>= 0)
    d.countedAt = tolerance;
    d.out.voxel = voxelOf(queries[r.witness], v.dims);
    d.out.nearestVoxel = voxelOf(targets[nearest[r.witness]], v.dims);
    finishDirection(v, d);
    return d;
}

void directionNumbers(const MaskOptions& options, Direction& d) {
    d.numbered = true;
    d.out.percentiles.clear();
    const ConventionRules& rules = conventionRules(options.convention);
    if (rules.surfaceMeasures) {  // else combine reports NaN
        const double limit = toleranceLimit(options);
        if (d.countedAt != limit) {
            d.withinTolerance = countAtMost(d.distances, limit, options.threads);
            d.countedAt = limit;
        }
        d.out.surfaceOverlap = double(d.withinTolerance) / double(d.out.points);
    }
    if (rules.percentile == DirectedPercentile::kNone) return;
    for (double p : options.percentiles) d.out.percentiles.push_back(directedPercentile(options, d, p));
}

Result<std::array<Direction, 2>> directionsOfOneCall(Engine& engine, const PairCall& call,
                                                     const VoxelMetric& metric,
                                                     const std::array<Side, 2>& sides,
                                                     const MaskOptions& options, MaskResult& timed) {
    const auto t0 = Clock::now();
    std::array<std::optional<Result<Direction>>, 2> done;
    CallOptions handed = perPointCall(false);
    // Each direction's work as the engine hands it back
    // (CallOptions::perPointReady; nothing may throw out of it). One handed
    // back on another thread than this one runs beside the engine's (on a
    // GPU, polling its fences while it searches the other direction): one
    // host thread fewer for it. On this thread (the CPU backend's
    // hand-backs, a GPU's last) the engine is idle.
    MaskOptions beside = options;
    beside.threads = std::max(1, core::resolveThreads(options.threads) - 1);
    const std::thread::id caller = std::this_thread::get_id();
    handed.perPointReady = [&](int k, std::span<const uint32_t> nearest) {
        const Side& s = sides[size_t(k)];
        const MaskOptions& use = std::this_thread::get_id() != caller ? beside : options;
        try {
            Result<Direction> d = directionOf(*s.grid, metric, s.queries, nearest, s.targets, 0,
                                              toleranceLimit(use), use.threads);
            if (d) directionNumbers(use, *d);
            done[size_t(k)] = std::move(d);
        } catch (const std::bad_alloc&) {
            done[size_t(k)] =
                Error{ErrorCode::kOutOfMemory, "masks: out of host memory for a direction's distances"};
        } catch (const std::exception& e) {  // on the engine's thread nothing may escape (std::terminate)
            done[size_t(k)] =
                Error{ErrorCode::kInternal, std::string("masks: a direction's distances: ") + e.what()};
        }
    };
    Result<HausdorffResult> r = call(handed);
    if (!r) return r.error();
    addTimings(timed.engine, r->timings);
    std::array<Direction, 2> out;
    for (size_t k = 0; k < 2; ++k) {
        if (!done[k]) return Error{ErrorCode::kInternal, "masks: the engine handed no nearest points back"};
        if (!*done[k]) return done[k]->error();
        out[k] = std::move(**done[k]);
    }
    engine.recycle(std::move(*r));  // its arrays serve the next comparison
    timed.distanceMs += msSince(t0);
    return out;
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
    d = directionOf(v, metric, queries, r->aNearest.nearest, targets, zeros, 0.0, threads);
    timed.distanceMs += msSince(t0);
    return d;
}

void setEmpty(uint64_t na, uint64_t nb, const std::vector<double>& percentiles, MaskResult& r) {
    r.empty = na == 0 && nb == 0 ? EmptyStatus::kBothEmpty
              : na == 0          ? EmptyStatus::kAEmpty
                                 : EmptyStatus::kBEmpty;
    const bool noPercentile = conventionRules(r.convention).percentile == DirectedPercentile::kNone;
    r.emptyValues = emptyValues(r.convention, r.empty, noPercentile ? std::vector<double>{} : percentiles);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    r.hd = r.assd = r.msd = r.surfaceDice = nan;
    r.hdPercentile.assign(noPercentile ? 0 : percentiles.size(), nan);
    for (DirectedMask* d : {&r.aToB, &r.bToA}) {
        d->hd = d->mean = d->surfaceOverlap = nan;
        d->percentiles.assign(noPercentile ? 0 : percentiles.size(), nan);
    }
    r.aToB.points = na;
    r.bToA.points = nb;
}

double toleranceLimit(const MaskOptions& options) {
    const double t = options.tolerance;
    if (!conventionRules(options.convention).float32Tolerance || !options.monaiFloat32) return t;
    // float(d) <= f for every d below the midpoint m of f and the next float
    // up; at m itself when rounding to even picks f.
    const float f = float(t);
    const float up = std::nextafter(f, std::numeric_limits<float>::infinity());
    if (!std::isfinite(f) || !std::isfinite(up)) return std::numeric_limits<double>::infinity();
    const double m = 0.5 * (double(f) + double(up));  // exact: two adjacent floats
    const bool even = (std::bit_cast<uint32_t>(f) & 1u) == 0;
    return even ? m : std::nextafter(m, -std::numeric_limits<double>::infinity());
}

void combine(const MaskOptions& options, Direction& ab, Direction& ba, MaskResult& r) {
    for (Direction* d : {&ab, &ba})
        if (!d->numbered) directionNumbers(options, *d);
    summarise(ab, ba, r);
    const ConventionRules& rules = conventionRules(options.convention);
    if (!rules.surfaceMeasures)
        r.assd = r.surfaceDice = ab.out.surfaceOverlap = ba.out.surfaceOverlap =
            std::numeric_limits<double>::quiet_NaN();
    addPercentiles(rules.combination, options.percentiles, ab, ba, options.threads, r);
    r.aToB = std::move(ab.out);
    r.bToA = std::move(ba.out);
}

}  // namespace rthdist::masks::detail
