// DeepMind surface-distance on the exact engine (masks.hpp has the
// definition). Per direction X -> Y: X's surfels that are also surfels of Y
// are at distance 0 and are not sent to the engine; the others query Y's
// surfels in the spacing metric, as float coordinates centred on the volume
// (VoxelMetric::corners: the frame and bound of voxel_metric.hpp, one frame
// for both directions, so a prepared reference's surfels serve either), and
// each distance is recomputed from the engine's nearest surfel the way
// SciPy's EDT computes it. The (distance, area) pairs are then sorted as
// DeepMind sorts them and every statistic is summed in NumPy's order.
#include "masks/deepmind.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "masks/area_weighted.hpp"
#include "masks/per_point_call.hpp"
#include "masks/surfel_area.hpp"
#include "masks/surfels.hpp"

namespace rthdist::masks::detail {
namespace {

struct SurfelDirection {
    std::vector<double> distances, areas;  // sorted by (distance, area)
    DirectedMask out;
    double weightedSum = 0.0;  // numpy.sum(distances * areas)
};

struct Timing {
    double extractMs = 0.0, distanceMs = 0.0;
};

glm::dvec3 cornerWorld(const Volume& v, std::array<int64_t, 3> c) {
    return glm::dvec3(v.voxelToWorld *
                      glm::dvec4(double(c[0]) - 0.5, double(c[1]) - 0.5, double(c[2]) - 0.5, 1.0));
}

// scipy.ndimage.distance_transform_edt's arithmetic for the offset p - q.
double edtDistance(std::array<int64_t, 3> p, std::array<int64_t, 3> q, glm::dvec3 s) {
    const double x = double(p[0] - q[0]) * s.x, y = double(p[1] - q[1]) * s.y, z = double(p[2] - q[2]) * s.z;
    return std::sqrt((x * x + y * y) + z * z);
}

// X's surfels split into those Y also has (distance 0) and the others.
void splitCommon(const Surfels& x, const Surfels& y, std::vector<size_t>& common, std::vector<size_t>& rest) {
    size_t j = 0;
    for (size_t i = 0; i < x.corners.size(); ++i) {
        while (j < y.corners.size() && y.corners[j] < x.corners[i]) ++j;
        (j < y.corners.size() && y.corners[j] == x.corners[i] ? common : rest).push_back(i);
    }
}

// Sorts the pairs as DeepMind does (by distance, then area) and fills the sums.
void finish(std::vector<std::pair<double, double>>& pairs, SurfelDirection& d) {
    std::sort(pairs.begin(), pairs.end());
    d.distances.resize(pairs.size());
    d.areas.resize(pairs.size());
    std::vector<double> products(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
        d.distances[i] = pairs[i].first;
        d.areas[i] = pairs[i].second;
        products[i] = pairs[i].first * pairs[i].second;
    }
    d.out.points = pairs.size();
    d.out.hd = d.distances.back();
    d.out.area = numpySum(d.areas);
    d.weightedSum = numpySum(products);
    d.out.mean = d.weightedSum / d.out.area;
}

// The engine's nearest surfel of Y for each of `rest` (X's corners Y lacks),
// searched in `metric`; the (distance, area) pairs with EDT distances on X's
// grid `v`, and the farthest pair's corners in from/to.
Result<std::vector<std::pair<double, double>>> searched(
    const VoxelMetric& metric, const Volume& v, const Surfels& x, const Surfels& y,
    const std::vector<size_t>& rest, const std::array<double, 256>& area, const NearestCall& nearestOf,
    int threads, Timing& timing, std::array<int64_t, 3>& from, std::array<int64_t, 3>& to) {
    auto t0 = Clock::now();
    std::vector<uint64_t> queries(rest.size());
    for (size_t i = 0; i < rest.size(); ++i) queries[i] = x.corners[rest[i]];
    const SearchPoints q = metric.searchPoints(queries, threads);
    timing.extractMs += msSince(t0);
    t0 = Clock::now();
    Result<HausdorffResult> r = nearestOf(q);
    timing.distanceMs += msSince(t0);
    if (!r) return r.error();
    const std::vector<uint32_t>& nearest = r->aNearest.nearest;
    if (nearest.size() != rest.size())
        return Error{ErrorCode::kInternal, "masks: the engine returned no per-point nearest points"};
    const glm::dvec3 s = v.spacing();
    std::vector<std::pair<double, double>> pairs;
    pairs.reserve(rest.size());
    double worst = -1.0;
    for (size_t i = 0; i < rest.size(); ++i) {
        const auto p = cornerOf(queries[i], v.dims), n = cornerOf(y.corners[nearest[i]], v.dims);
        const double dist = edtDistance(p, n, s);
        pairs.push_back({dist, area[x.codes[rest[i]]]});
        if (dist > worst) {
            worst = dist;
            from = p;
            to = n;
        }
    }
    return pairs;
}

// X -> Y: X's surfels that Y also has at 0, the others through `nearestOf`.
Result<SurfelDirection> directed(const VoxelMetric& metric, const Volume& v, const Surfels& x,
                                 const Surfels& y, const std::array<double, 256>& area,
                                 const NearestCall& nearestOf, int threads, Timing& timing) {
    SurfelDirection d;
    std::vector<size_t> common, rest;
    splitCommon(x, y, common, rest);
    std::vector<std::pair<double, double>> pairs;
    pairs.reserve(x.corners.size());
    for (size_t i : common) pairs.push_back({0.0, area[x.codes[i]]});
    std::array<int64_t, 3> from = cornerOf(x.corners[common.empty() ? 0 : common[0]], v.dims), to = from;
    if (!rest.empty()) {
        Result<std::vector<std::pair<double, double>>> far =
            searched(metric, v, x, y, rest, area, nearestOf, threads, timing, from, to);
        if (!far) return far.error();
        pairs.insert(pairs.end(), far->begin(), far->end());
    }
    finish(pairs, d);
    d.out.voxel = from;
    d.out.nearestVoxel = to;
    d.out.point = cornerWorld(v, from);
    d.out.nearestPoint = cornerWorld(v, to);
    return d;
}

// One-shot searches against Y's surfels.
NearestCall oneShot(Engine& engine, const VoxelMetric& metric, const Surfels& y, int threads,
                    Timing& timing) {
    return [&engine, &metric, &y, threads, &timing](std::span<const glm::vec3> q) -> Result<HausdorffResult> {
        auto t0 = Clock::now();
        const SearchPoints t = metric.searchPoints(y.corners, threads);
        timing.extractMs += msSince(t0);
        return engine.compute(PointView(q), PointView(t), perPointCall(true));
    };
}

// Area of the direction's surfels within `tolerance` (a prefix of the sorted distances).
double areaWithin(const SurfelDirection& d, double tolerance) {
    const size_t n =
        size_t(std::upper_bound(d.distances.begin(), d.distances.end(), tolerance) - d.distances.begin());
    return numpySum(std::span<const double>(d.areas).first(n));
}

// The numbers of both directions, area-weighted.
MaskResult summary(const MaskOptions& options, SurfelDirection& ab, SurfelDirection& ba, const Timing& timing,
                   Clock::time_point start) {
    MaskResult r;
    r.convention = options.convention;
    r.connectivity = 0;
    r.percentiles = options.percentiles;
    r.hd = std::max(ab.out.hd, ba.out.hd);
    for (double p : options.percentiles) {
        ab.out.percentiles.push_back(areaWeightedPercentile(ab.distances, ab.areas, p));
        ba.out.percentiles.push_back(areaWeightedPercentile(ba.distances, ba.areas, p));
        r.hdPercentile.push_back(std::max(ab.out.percentiles.back(), ba.out.percentiles.back()));
    }
    const double withinA = areaWithin(ab, options.tolerance), withinB = areaWithin(ba, options.tolerance);
    ab.out.surfaceOverlap = withinA / ab.out.area;
    ba.out.surfaceOverlap = withinB / ba.out.area;
    r.surfaceDice = (withinA + withinB) / (ab.out.area + ba.out.area);
    r.assd = (ab.weightedSum + ba.weightedSum) / (ab.out.area + ba.out.area);
    r.msd = 0.5 * (ab.out.mean + ba.out.mean);
    r.aToB = std::move(ab.out);
    r.bToA = std::move(ba.out);
    r.extractMs = timing.extractMs;
    r.distanceMs = timing.distanceMs;
    r.totalMs = msSince(start);
    return r;
}

}  // namespace

Result<MaskResult> compareDeepmind(Engine& engine, const Volume& a, LabelSelect selectA, const Volume& b,
                                   LabelSelect selectB, const MaskOptions& options) {
    const auto start = Clock::now();
    const Surfels sa = extractSurfels(a, selectA, options.threads);
    const Surfels sb = extractSurfels(b, selectB, options.threads);
    return compareSurfels(engine, a, sa, b, sb, options, nullptr, msSince(start), start);
}

Result<MaskResult> compareSurfels(Engine& engine, const Volume& a, const Surfels& sa, const Volume& b,
                                  const Surfels& sb, const MaskOptions& options, const NearestCall* toA,
                                  double extractMs, Clock::time_point start) {
    Timing timing;
    timing.extractMs = extractMs;
    if (sa.selected == 0 || sb.selected == 0) {
        MaskResult r;
        r.convention = options.convention;
        r.connectivity = 0;
        r.percentiles = options.percentiles;
        setEmpty(sa.corners.size(), sb.corners.size(), options.percentiles, r);
        r.extractMs = timing.extractMs;
        r.totalMs = msSince(start);
        return r;
    }
    const std::array<double, 256> area = surfelAreaTable(a.spacing());
    const VoxelMetric metric = VoxelMetric::corners(a);
    Result<SurfelDirection> ab =
        directed(metric, a, sa, sb, area, oneShot(engine, metric, sb, options.threads, timing),
                 options.threads, timing);
    if (!ab) return ab.error();
    Result<SurfelDirection> ba =
        directed(metric, b, sb, sa, area, toA ? *toA : oneShot(engine, metric, sa, options.threads, timing),
                 options.threads, timing);
    if (!ba) return ba.error();
    return summary(options, *ab, *ba, timing, start);
}

}  // namespace rthdist::masks::detail
