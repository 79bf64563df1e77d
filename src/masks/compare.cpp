// Mask comparison in a named convention (masks.hpp has the definitions;
// ../shared/MASKS.md the peers' sources they were read from).
//
// Both directions run on the exact engine with per-point distances. Work the
// convention makes trivially zero is not sent to the engine: a boundary voxel
// of X that is also a boundary voxel of Y has distance 0, and (itk) a voxel of
// X inside Y has distance 0 while the nearest voxel of Y to any voxel outside
// Y is one of Y's 6-connected boundary voxels (a step from an interior voxel
// towards the query along its largest axis gets closer and stays in Y). The
// zeros still count in every mean, percentile and surface Dice. The deepmind
// convention (surfels with areas) lives in deepmind.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>

#include "core/parallel.hpp"
#include "masks/boundary.hpp"
#include "masks/deepmind.hpp"
#include "masks/masks.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::masks {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Linear interpolation between order statistics (numpy.percentile's and
// torch.quantile's default): rank q (n - 1), lerp written as numpy writes it.
double percentileLinear(const std::vector<double>& sorted, double p) {
    const size_t n = sorted.size();
    if (n == 0) return std::numeric_limits<double>::quiet_NaN();
    const double rank = (p / 100.0) * double(n - 1);
    const double lo = std::floor(rank);
    const size_t i = std::min(size_t(lo), n - 1), j = std::min(i + 1, n - 1);
    const double t = rank - lo;
    const double a = sorted[i], b = sorted[j];
    const double diff = b - a;
    return t >= 0.5 ? b - diff * (1.0 - t) : a + diff * t;
}

// plastimatch: the k-th smallest (0-based), k = floor(f n - 1) clamped to [0, n-1].
double percentilePlastimatch(const std::vector<double>& sorted, double p) {
    const size_t n = sorted.size();
    if (n == 0) return 0.0;
    double k = std::floor((p / 100.0) * double(n) - 1.0);
    k = std::clamp(k, 0.0, double(n - 1));
    return sorted[size_t(k)];
}

struct Direction {
    std::vector<double> sorted;  // all of X's distances, ascending (zeros included)
    DirectedMask out;
    double sum = 0.0;
};

// MONAI and plastimatch have no connectivity parameter (SciPy's default cross;
// plastimatch's face neighbours): 6 whatever is asked. rthdist and MedPy take one.
int connectivityOf(Convention c, int requested) {
    const bool configurable = c == Convention::kRthdist || c == Convention::kMedpy;
    return configurable && requested != 0 ? requested : 6;
}

glm::dvec3 worldOf(const Volume& v, std::array<int64_t, 3> ijk) {
    return glm::dvec3(v.voxelToWorld * glm::dvec4(double(ijk[0]), double(ijk[1]), double(ijk[2]), 1.0));
}

// Coordinates of voxels: the full affine (world) or the spacing only.
std::vector<glm::dvec3> coordinates(const std::vector<uint64_t>& voxels, const Volume& v, bool world,
                                    int threads) {
    std::vector<glm::dvec3> out(voxels.size());
    const glm::dvec3 s = v.spacing();
    core::parallelChunks(voxels.size(), size_t(1) << 16, threads, [&](size_t b, size_t e, int) {
        for (size_t i = b; i < e; ++i) {
            const auto ijk = detail::voxelOf(voxels[i], v.dims);
            out[i] = world ? worldOf(v, ijk)
                           : glm::dvec3(double(ijk[0]) * s.x, double(ijk[1]) * s.y, double(ijk[2]) * s.z);
        }
    });
    return out;
}

// One direction: `queries` (X's voxels that may be non-zero), `zeros` more of
// X's voxels at distance 0 (zeroWitness: one of them, or ~0 when none),
// `targets` (Y's voxels). Fills the direction's sorted distances and witness.
Result<Direction> directed(Engine& engine, const Volume& v, const std::vector<uint64_t>& queries,
                           uint64_t zeros, uint64_t zeroWitness, const std::vector<uint64_t>& targets,
                           bool world, int threads, double& extractMs, double& distanceMs) {
    Direction d;
    d.out.points = queries.size() + zeros;
    d.sorted.assign(size_t(zeros), 0.0);
    if (!queries.empty()) {
        auto t0 = Clock::now();
        const std::vector<glm::dvec3> q = coordinates(queries, v, world, threads);
        const std::vector<glm::dvec3> t = coordinates(targets, v, world, threads);
        extractMs += msSince(t0);
        t0 = Clock::now();
        Result<HausdorffResult> r = engine.compute(PointView(q), PointView(t));
        distanceMs += msSince(t0);
        if (!r) return r.error();
        const std::vector<double>& dist = r->aNearest.distance;
        if (dist.size() != queries.size())
            return Error{ErrorCode::kInternal, "masks: the engine returned no per-point distances"};
        d.sorted.insert(d.sorted.end(), dist.begin(), dist.end());
        std::sort(d.sorted.begin() + ptrdiff_t(zeros), d.sorted.end());
        for (double x : dist) d.sum += x;
        d.out.hd = r->aToB.distance;
        d.out.voxel = detail::voxelOf(queries[r->aToB.queryIndex], v.dims);
        d.out.nearestVoxel = detail::voxelOf(targets[r->aToB.targetIndex], v.dims);
    } else {
        d.out.hd = 0.0;
        d.out.voxel = d.out.nearestVoxel = detail::voxelOf(zeroWitness, v.dims);
    }
    d.out.point = worldOf(v, d.out.voxel);
    d.out.nearestPoint = worldOf(v, d.out.nearestVoxel);
    d.out.mean = d.out.points ? d.sum / double(d.out.points) : 0.0;
    return d;
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

}  // namespace

const char* conventionName(Convention c) {
    switch (c) {
        case Convention::kRthdist: return "rthdist";
        case Convention::kMonai: return "monai";
        case Convention::kMedpy: return "medpy";
        case Convention::kPlastimatch: return "plastimatch";
        case Convention::kItk: return "itk";
        case Convention::kDeepmind: return "deepmind";
    }
    return "?";
}

bool parseConvention(const std::string& text, Convention& out) {
    for (Convention c : kAllConventions) {
        if (text == conventionName(c)) {
            out = c;
            return true;
        }
    }
    return false;
}

const char* conventionRule(Convention c) {
    switch (c) {
        case Convention::kRthdist:
            return "boundary voxels (connectivity), world coordinates (affine); HD-p = max of the two "
                   "directed "
                   "nearest-rank percentiles";
        case Convention::kMonai:
            return "mask XOR erosion (6-connected), spacing; HD-p = max of the two directed linear "
                   "percentiles "
                   "(torch.quantile)";
        case Convention::kMedpy:
            return "mask XOR erosion (connectivity), spacing; HD-p = linear percentile of both directions "
                   "pooled";
        case Convention::kPlastimatch:
            return "boundary voxels (6-connected), spacing; HD-p = mean of the two directed k-th smallest, "
                   "k = floor(p/100 n - 1)";
        case Convention::kItk:
            return "all foreground voxels (inside the other = 0), spacing; HD only; average = mean of the "
                   "directed means";
        case Convention::kDeepmind:
            return "surfels on the half-voxel-shifted grid with marching-cubes areas, spacing; HD-p = max of "
                   "the two directed area-weighted percentiles (first cumulative area fraction >= p/100)";
    }
    return "?";
}

const char* emptyStatusName(EmptyStatus s) {
    switch (s) {
        case EmptyStatus::kNone: return "ok";
        case EmptyStatus::kBothEmpty: return "both_empty";
        case EmptyStatus::kAEmpty: return "a_empty";
        case EmptyStatus::kBEmpty: return "b_empty";
    }
    return "?";
}

Result<Engine> makeMaskEngine(Options options) {
    options.perPointDistances = true;
    options.directedOnly = true;
    return Engine::create(options);
}

Result<MaskResult> compareMasks(Engine& engine, const Volume& a, LabelSelect selectA, const Volume& b,
                                LabelSelect selectB, const MaskOptions& options) {
    const auto start = Clock::now();
    if (auto e = checkSameGrid(a, b)) return *e;
    if (a.storedVoxels() != a.voxelCount() || b.storedVoxels() != b.voxelCount())
        return Error{ErrorCode::kInvalidArgument, "masks: label array size differs from the dimensions"};
    if (options.connectivity != 0 && options.connectivity != 6 && options.connectivity != 18 &&
        options.connectivity != 26)
        return Error{ErrorCode::kInvalidArgument, "masks: connectivity must be 6, 18 or 26"};
    for (double p : options.percentiles)
        if (!(p >= 0.0 && p <= 100.0))
            return Error{ErrorCode::kInvalidArgument, "masks: percentile outside [0, 100]"};
    if (!(options.tolerance >= 0.0))
        return Error{ErrorCode::kInvalidArgument, "masks: tolerance must be >= 0"};

    const Convention c = options.convention;
    if (c == Convention::kDeepmind) return detail::compareDeepmind(engine, a, selectA, b, selectB, options);
    const int conn = connectivityOf(c, options.connectivity);
    const bool itk = c == Convention::kItk;
    MaskResult r;
    r.convention = c;
    r.connectivity = itk ? 0 : conn;
    r.percentiles = options.percentiles;
    const int threads = options.threads;
    const bool world = c == Convention::kRthdist;

    auto t0 = Clock::now();
    const detail::Extraction ea = detail::extractBoundary(a, selectA, itk ? 6 : conn, threads);
    const detail::Extraction eb = detail::extractBoundary(b, selectB, itk ? 6 : conn, threads);
    const uint64_t na = ea.count, nb = eb.count;
    if (na == 0 || nb == 0) {
        r.empty = na == 0 && nb == 0 ? EmptyStatus::kBothEmpty
                  : na == 0          ? EmptyStatus::kAEmpty
                                     : EmptyStatus::kBEmpty;
        emptyValues(c, r.empty, r);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        r.hd = r.assd = r.msd = r.surfaceDice = nan;
        r.hdPercentile.assign(itk ? 0 : options.percentiles.size(), nan);
        r.aToB.hd = r.bToA.hd = r.aToB.mean = r.bToA.mean = nan;
        r.aToB.surfaceOverlap = r.bToA.surfaceOverlap = nan;
        r.extractMs = msSince(t0);
        r.totalMs = msSince(start);
        return r;
    }

    // Queries (possibly non-zero), zero count and targets per direction.
    const std::vector<uint64_t>& ba = ea.boundary;
    const std::vector<uint64_t>& bb = eb.boundary;
    std::vector<uint64_t> qa, qb;
    uint64_t za = 0, zb = 0, zwa = 0, zwb = 0;
    if (itk) {
        qa = detail::differenceVoxels(a, selectA, b, selectB, threads);
        qb = detail::differenceVoxels(b, selectB, a, selectA, threads);
        za = na - qa.size();
        zb = nb - qb.size();
        // A zero-distance witness: a voxel in both masks.
        if (za > 0 || zb > 0) zwa = zwb = detail::firstCommonVoxel(a, selectA, b, selectB).value_or(0);
    } else {
        std::set_difference(ba.begin(), ba.end(), bb.begin(), bb.end(), std::back_inserter(qa));
        std::set_difference(bb.begin(), bb.end(), ba.begin(), ba.end(), std::back_inserter(qb));
        za = ba.size() - qa.size();
        zb = bb.size() - qb.size();
        if (za > 0 || zb > 0) {
            std::vector<uint64_t> common;
            std::set_intersection(ba.begin(), ba.end(), bb.begin(), bb.end(), std::back_inserter(common));
            zwa = zwb = common.front();
        }
    }
    r.extractMs = msSince(t0);

    Result<Direction> ab = directed(engine, a, qa, za, zwa, bb, world, threads, r.extractMs, r.distanceMs);
    if (!ab) return ab.error();
    Result<Direction> ba2 = directed(engine, b, qb, zb, zwb, ba, world, threads, r.extractMs, r.distanceMs);
    if (!ba2) return ba2.error();
    Direction& da = *ab;
    Direction& db = *ba2;

    r.hd = std::max(da.out.hd, db.out.hd);
    const double nAll = double(da.out.points + db.out.points);
    r.assd = (da.sum + db.sum) / nAll;
    r.msd = 0.5 * (da.out.mean + db.out.mean);
    uint64_t within = 0;
    for (Direction* d : {&da, &db}) {
        const uint64_t w = uint64_t(std::upper_bound(d->sorted.begin(), d->sorted.end(), options.tolerance) -
                                    d->sorted.begin());
        d->out.surfaceOverlap = double(w) / double(d->out.points);
        within += w;
    }
    r.surfaceDice = double(within) / nAll;

    std::vector<double> pooled;
    if (c == Convention::kMedpy) {
        pooled.resize(da.sorted.size() + db.sorted.size());
        std::merge(da.sorted.begin(), da.sorted.end(), db.sorted.begin(), db.sorted.end(), pooled.begin());
    }
    for (double p : options.percentiles) {
        double pa = 0.0, pb = 0.0, combined = 0.0;
        switch (c) {
            case Convention::kRthdist:
                pa = percentileNearestRank(da.sorted, p);
                pb = percentileNearestRank(db.sorted, p);
                combined = std::max(pa, pb);
                break;
            case Convention::kMonai:
                pa = percentileLinear(da.sorted, p);
                pb = percentileLinear(db.sorted, p);
                combined = std::max(pa, pb);
                break;
            case Convention::kMedpy:
                pa = percentileLinear(da.sorted, p);
                pb = percentileLinear(db.sorted, p);
                combined = percentileLinear(pooled, p);
                break;
            case Convention::kPlastimatch:
                pa = percentilePlastimatch(da.sorted, p);
                pb = percentilePlastimatch(db.sorted, p);
                combined = 0.5 * (pa + pb);
                break;
            case Convention::kItk:
            case Convention::kDeepmind: break;
        }
        if (!itk) {
            da.out.percentiles.push_back(pa);
            db.out.percentiles.push_back(pb);
            r.hdPercentile.push_back(combined);
        }
    }
    if (itk)
        r.assd = r.surfaceDice = da.out.surfaceOverlap = db.out.surfaceOverlap =
            std::numeric_limits<double>::quiet_NaN();
    r.aToB = std::move(da.out);
    r.bToA = std::move(db.out);
    r.totalMs = msSince(start);
    return r;
}

}  // namespace rthdist::masks
