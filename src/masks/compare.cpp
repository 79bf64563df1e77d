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
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

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

// The checks of compareMasks that every convention shares.
std::optional<Error> checkInputs(const Volume& a, const Volume& b, const MaskOptions& options) {
    if (auto e = checkSameGrid(a, b)) return e;
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
    return std::nullopt;
}

// One direction's points: X's voxels that may be non-zero, how many more of
// X's voxels are at distance 0, and one of those (0 when none).
struct DirectionPoints {
    std::vector<uint64_t> queries;
    uint64_t zeros = 0;
    uint64_t zeroWitness = 0;
};

// itk: all foreground voxels; a voxel of X inside Y has distance 0.
std::array<DirectionPoints, 2> itkPoints(const Volume& a, LabelSelect selectA, uint64_t na, const Volume& b,
                                         LabelSelect selectB, uint64_t nb, int threads) {
    std::array<DirectionPoints, 2> d;
    d[0].queries = detail::differenceVoxels(a, selectA, b, selectB, threads);
    d[1].queries = detail::differenceVoxels(b, selectB, a, selectA, threads);
    d[0].zeros = na - d[0].queries.size();
    d[1].zeros = nb - d[1].queries.size();
    // A zero-distance witness: a voxel in both masks.
    if (d[0].zeros > 0 || d[1].zeros > 0)
        d[0].zeroWitness = d[1].zeroWitness = detail::firstCommonVoxel(a, selectA, b, selectB).value_or(0);
    return d;
}

// Boundary conventions: a boundary voxel of X that is also one of Y has distance 0.
std::array<DirectionPoints, 2> boundaryPoints(const std::vector<uint64_t>& ba,
                                              const std::vector<uint64_t>& bb) {
    std::array<DirectionPoints, 2> d;
    std::set_difference(ba.begin(), ba.end(), bb.begin(), bb.end(), std::back_inserter(d[0].queries));
    std::set_difference(bb.begin(), bb.end(), ba.begin(), ba.end(), std::back_inserter(d[1].queries));
    d[0].zeros = ba.size() - d[0].queries.size();
    d[1].zeros = bb.size() - d[1].queries.size();
    if (d[0].zeros > 0 || d[1].zeros > 0) {
        std::vector<uint64_t> common;
        std::set_intersection(ba.begin(), ba.end(), bb.begin(), bb.end(), std::back_inserter(common));
        d[0].zeroWitness = d[1].zeroWitness = common.front();
    }
    return d;
}

// HD, ASSD, MSD, surface overlaps and surface Dice from both directions.
void summarise(Direction& da, Direction& db, double tolerance, MaskResult& r) {
    r.hd = std::max(da.out.hd, db.out.hd);
    const double nAll = double(da.out.points + db.out.points);
    r.assd = (da.sum + db.sum) / nAll;
    r.msd = 0.5 * (da.out.mean + db.out.mean);
    uint64_t within = 0;
    for (Direction* d : {&da, &db}) {
        const uint64_t w =
            uint64_t(std::upper_bound(d->sorted.begin(), d->sorted.end(), tolerance) - d->sorted.begin());
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

PercentilePair percentilesOf(Convention c, const Direction& da, const Direction& db,
                             const std::vector<double>& pooled, double p) {
    PercentilePair v;
    switch (c) {
        case Convention::kRthdist:
            v.a = percentileNearestRank(da.sorted, p);
            v.b = percentileNearestRank(db.sorted, p);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMonai:
            v.a = percentileLinear(da.sorted, p);
            v.b = percentileLinear(db.sorted, p);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMedpy:
            v.a = percentileLinear(da.sorted, p);
            v.b = percentileLinear(db.sorted, p);
            v.combined = percentileLinear(pooled, p);
            break;
        case Convention::kPlastimatch:
            v.a = percentilePlastimatch(da.sorted, p);
            v.b = percentilePlastimatch(db.sorted, p);
            v.combined = 0.5 * (v.a + v.b);
            break;
        case Convention::kItk:
        case Convention::kDeepmind: break;
    }
    return v;
}

// Every requested HD-p, per direction and combined (not for itk).
void addPercentiles(Convention c, const std::vector<double>& percentiles, Direction& da, Direction& db,
                    MaskResult& r) {
    std::vector<double> pooled;
    if (c == Convention::kMedpy) {
        pooled.resize(da.sorted.size() + db.sorted.size());
        std::merge(da.sorted.begin(), da.sorted.end(), db.sorted.begin(), db.sorted.end(), pooled.begin());
    }
    for (double p : percentiles) {
        const PercentilePair v = percentilesOf(c, da, db, pooled, p);
        da.out.percentiles.push_back(v.a);
        db.out.percentiles.push_back(v.b);
        r.hdPercentile.push_back(v.combined);
    }
}

// Each convention's name and one-line rule, in kAllConventions order.
struct ConventionText {
    Convention convention;
    const char* name;
    const char* rule;
};

constexpr std::array<ConventionText, kAllConventions.size()> kConventionTexts{{
    {Convention::kRthdist, "rthdist",
     "boundary voxels (connectivity), world coordinates (affine); HD-p = max of the two directed "
     "nearest-rank percentiles"},
    {Convention::kMonai, "monai",
     "mask XOR erosion (6-connected), spacing; HD-p = max of the two directed linear percentiles "
     "(torch.quantile)"},
    {Convention::kMedpy, "medpy",
     "mask XOR erosion (connectivity), spacing; HD-p = linear percentile of both directions pooled"},
    {Convention::kPlastimatch, "plastimatch",
     "boundary voxels (6-connected), spacing; HD-p = mean of the two directed k-th smallest, "
     "k = floor(p/100 n - 1)"},
    {Convention::kItk, "itk",
     "all foreground voxels (inside the other = 0), spacing; HD only; average = mean of the directed means"},
    {Convention::kDeepmind, "deepmind",
     "surfels on the half-voxel-shifted grid with marching-cubes areas, spacing; HD-p = max of the two "
     "directed area-weighted percentiles (first cumulative area fraction >= p/100)"},
}};

constexpr bool conventionTextsInOrder() {
    for (size_t i = 0; i < kConventionTexts.size(); ++i) {
        if (kConventionTexts[i].convention != kAllConventions[i] || size_t(kAllConventions[i]) != i)
            return false;
    }
    return true;
}
static_assert(conventionTextsInOrder(), "kConventionTexts[i] describes Convention(i)");

const ConventionText* textOf(Convention c) {
    return size_t(c) < kConventionTexts.size() ? &kConventionTexts[size_t(c)] : nullptr;
}

}  // namespace

const char* conventionName(Convention c) {
    const ConventionText* t = textOf(c);
    return t != nullptr ? t->name : "?";
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
    const ConventionText* t = textOf(c);
    return t != nullptr ? t->rule : "?";
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
    if (auto e = checkInputs(a, b, options)) return *e;
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
    if (ea.count == 0 || eb.count == 0) {
        setEmpty(ea.count, eb.count, itk ? 0 : options.percentiles.size(), r);
        r.extractMs = msSince(t0);
        r.totalMs = msSince(start);
        return r;
    }
    // Queries (possibly non-zero), zero count and targets per direction.
    const std::array<DirectionPoints, 2> p =
        itk ? itkPoints(a, selectA, ea.count, b, selectB, eb.count, threads)
            : boundaryPoints(ea.boundary, eb.boundary);
    r.extractMs = msSince(t0);

    Result<Direction> ab = directed(engine, a, p[0].queries, p[0].zeros, p[0].zeroWitness, eb.boundary, world,
                                    threads, r.extractMs, r.distanceMs);
    if (!ab) return ab.error();
    Result<Direction> ba = directed(engine, b, p[1].queries, p[1].zeros, p[1].zeroWitness, ea.boundary, world,
                                    threads, r.extractMs, r.distanceMs);
    if (!ba) return ba.error();
    summarise(*ab, *ba, options.tolerance, r);
    if (itk) {
        r.assd = r.surfaceDice = ab->out.surfaceOverlap = ba->out.surfaceOverlap =
            std::numeric_limits<double>::quiet_NaN();
    } else {
        addPercentiles(c, options.percentiles, *ab, *ba, r);
    }
    r.aToB = std::move(ab->out);
    r.bToA = std::move(ba->out);
    r.totalMs = msSince(start);
    return r;
}

}  // namespace rthdist::masks
