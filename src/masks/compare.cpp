// Mask comparison in a named convention (masks.hpp has the definitions;
// ../shared/MASKS.md the peers' sources they were read from).
//
// Both directions run on the exact engine with per-point distances: the
// boundary conventions in one call (both boundaries uploaded and indexed
// once; a voxel on both boundaries comes back at distance 0). itk sends less:
// a voxel of X inside Y has distance 0 while the nearest voxel of Y to any
// voxel outside Y is one of Y's 6-connected boundary voxels (a step from an
// interior voxel towards the query along its largest axis gets closer and
// stays in Y), so each direction queries X's voxels outside Y against Y's
// boundary; the zeros still count in every mean. Percentiles and counts come
// from selection, not sorting (order_statistics.hpp). The deepmind
// convention (surfels with areas) lives in deepmind.cpp.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

#include "core/timings.hpp"
#include "masks/boundary.hpp"
#include "masks/deepmind.hpp"
#include "masks/gpu_boundary.hpp"
#include "masks/masks.hpp"
#include "masks/order_statistics.hpp"
#include "masks/per_point_call.hpp"
#include "masks/voxel_metric.hpp"
#include "masks_gpu/boundary_pass.hpp"

namespace rthdist::masks {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Direction {
    std::vector<double> distances;  // all of X's distances, in no particular order (zeros included)
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

// X's side of an engine call: `queries` (X's voxels sent, in the call's
// order), `nearest` the engine's per-point output (indices into `targets`),
// plus `zeros` more of X's voxels at distance 0 that were not sent. Distances
// recomputed in double on X's grid `v` (voxel_metric.hpp).
Result<Direction> directionOf(const Volume& v, const detail::VoxelMetric& metric,
                              const std::vector<uint64_t>& queries, const PerPoint& nearest,
                              const std::vector<uint64_t>& targets, uint64_t zeros, int threads) {
    if (queries.empty() || nearest.nearest.size() != queries.size())
        return Error{ErrorCode::kInternal, "masks: the engine returned no per-point nearest points"};
    detail::RecomputedDirection r =
        detail::recompute(metric, v.dims, queries, targets, nearest.nearest, threads);
    Direction d;
    d.out.points = queries.size() + zeros;
    d.distances.reserve(size_t(d.out.points));
    d.distances.assign(size_t(zeros), 0.0);
    d.distances.insert(d.distances.end(), r.distances.begin(), r.distances.end());
    d.sum = r.sum;
    d.out.hd = r.distances[r.witness];
    d.out.voxel = detail::voxelOf(queries[r.witness], v.dims);
    d.out.nearestVoxel = detail::voxelOf(targets[nearest.nearest[r.witness]], v.dims);
    return d;
}

// The mean and world points of a filled direction on X's grid `v`.
void finishDirection(const Volume& v, Direction& d) {
    d.out.point = worldOf(v, d.out.voxel);
    d.out.nearestPoint = worldOf(v, d.out.nearestVoxel);
    d.out.mean = d.out.points ? d.sum / double(d.out.points) : 0.0;
}

// Adds one call's stage timings and its total to `sum` (the masks' calls
// run one after another, so their totals add up).
void addTimings(Timings& sum, const Timings& t) {
    core::addStageTimings(sum, t);
    sum.total += t.total;
}

// Boundary conventions: both directions in one engine call (each set
// uploaded and indexed once), every boundary voxel a query (a voxel on both
// boundaries comes back at distance 0). Both sets take A's grid (B's equals
// it: checkSameGrid); `timed` gains the extraction, distance and engine times.
Result<std::array<Direction, 2>> bothDirections(Engine& engine, const Volume& a,
                                                const std::vector<uint64_t>& ba, const Volume& b,
                                                const std::vector<uint64_t>& bb, bool world, int threads,
                                                MaskResult& timed) {
    auto t0 = Clock::now();
    const detail::VoxelMetric metric(a, world);
    const std::vector<glm::vec3> pa = metric.searchPoints(ba, threads);
    const std::vector<glm::vec3> pb = metric.searchPoints(bb, threads);
    timed.extractMs += msSince(t0);
    t0 = Clock::now();
    Result<HausdorffResult> r = engine.compute(PointView(pa), PointView(pb), detail::perPointCall(false));
    if (!r) return r.error();
    addTimings(timed.engine, r->timings);
    Result<Direction> ab = directionOf(a, metric, ba, r->aNearest, bb, 0, threads);
    if (!ab) return ab.error();
    Result<Direction> bA = directionOf(b, metric, bb, r->bNearest, ba, 0, threads);
    if (!bA) return bA.error();
    timed.distanceMs += msSince(t0);
    finishDirection(a, *ab);
    finishDirection(b, *bA);
    return std::array<Direction, 2>{std::move(*ab), std::move(*bA)};
}

// One direction (itk): `queries` (X's voxels that may be non-zero), `zeros`
// more of X's voxels at distance 0 (zeroWitness: one of them, or ~0 when
// none), `targets` (Y's voxels), all on X's grid `v`.
Result<Direction> directed(Engine& engine, const Volume& v, const std::vector<uint64_t>& queries,
                           uint64_t zeros, uint64_t zeroWitness, const std::vector<uint64_t>& targets,
                           int threads, MaskResult& timed) {
    Result<Direction> d = Direction{};
    if (!queries.empty()) {
        auto t0 = Clock::now();
        const detail::VoxelMetric metric(v, false);
        const std::vector<glm::vec3> q = metric.searchPoints(queries, threads);
        const std::vector<glm::vec3> t = metric.searchPoints(targets, threads);
        timed.extractMs += msSince(t0);
        t0 = Clock::now();
        Result<HausdorffResult> r = engine.compute(PointView(q), PointView(t), detail::perPointCall(true));
        if (!r) return r.error();
        addTimings(timed.engine, r->timings);
        d = directionOf(v, metric, queries, r->aNearest, targets, zeros, threads);
        if (!d) return d.error();
        timed.distanceMs += msSince(t0);
    } else {
        d->out.points = zeros;
        d->distances.assign(size_t(zeros), 0.0);
        d->out.hd = 0.0;
        d->out.voxel = d->out.nearestVoxel = detail::voxelOf(zeroWitness, v.dims);
    }
    finishDirection(v, *d);
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

// itk: each direction its own call (X's voxels outside Y against Y's boundary).
Result<std::array<Direction, 2>> itkDirections(Engine& engine, const Volume& a, LabelSelect selectA,
                                               const detail::Extraction& ea, const Volume& b,
                                               LabelSelect selectB, const detail::Extraction& eb, int threads,
                                               MaskResult& r) {
    const auto t0 = Clock::now();
    const std::array<DirectionPoints, 2> p = itkPoints(a, selectA, ea.count, b, selectB, eb.count, threads);
    r.extractMs += msSince(t0);
    Result<Direction> ab =
        directed(engine, a, p[0].queries, p[0].zeros, p[0].zeroWitness, eb.boundary, threads, r);
    if (!ab) return ab.error();
    Result<Direction> ba =
        directed(engine, b, p[1].queries, p[1].zeros, p[1].zeroWitness, ea.boundary, threads, r);
    if (!ba) return ba.error();
    return std::array<Direction, 2>{std::move(*ab), std::move(*ba)};
}

// Both masks' boundaries: through the device pass (one submission) when
// there is one, else (or when a box does not fit the pass) on the host.
// `where` becomes "device" when the pass found them.
Result<std::vector<detail::Extraction>> extractBoth(masks_gpu::BoundaryPass* pass,
                                                    const std::array<detail::MaskRef, 2>& masks,
                                                    int connectivity, int threads, std::string& where) {
    if (pass != nullptr) {
        Result<std::vector<detail::Extraction>> e =
            detail::extractBoundariesOnDevice(*pass, masks, connectivity, threads);
        if (e) {
            where = "device";
            return e;
        }
        if (e.error().code != ErrorCode::kOutOfMemory) return e.error();
    }
    std::vector<detail::Extraction> out;
    for (const detail::MaskRef& m : masks)
        out.push_back(detail::extractBoundary(*m.volume, m.select, connectivity, threads));
    return out;
}

// HD, ASSD, MSD, surface overlaps and surface Dice from both directions.
void summarise(Direction& da, Direction& db, double tolerance, MaskResult& r) {
    r.hd = std::max(da.out.hd, db.out.hd);
    const double nAll = double(da.out.points + db.out.points);
    r.assd = (da.sum + db.sum) / nAll;
    r.msd = 0.5 * (da.out.mean + db.out.mean);
    uint64_t within = 0;
    for (Direction* d : {&da, &db}) {
        const uint64_t w = detail::countAtMost(d->distances, tolerance);
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

PercentilePair percentilesOf(Convention c, Direction& da, Direction& db, std::vector<double>& pooled,
                             double p) {
    PercentilePair v;
    switch (c) {
        case Convention::kRthdist:
            v.a = detail::percentileNearestRank(da.distances, p);
            v.b = detail::percentileNearestRank(db.distances, p);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMonai:
            v.a = detail::percentileLinear(da.distances, p);
            v.b = detail::percentileLinear(db.distances, p);
            v.combined = std::max(v.a, v.b);
            break;
        case Convention::kMedpy:
            v.a = detail::percentileLinear(da.distances, p);
            v.b = detail::percentileLinear(db.distances, p);
            v.combined = detail::percentileLinear(pooled, p);
            break;
        case Convention::kPlastimatch:
            v.a = detail::percentilePlastimatch(da.distances, p);
            v.b = detail::percentilePlastimatch(db.distances, p);
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
        pooled.reserve(da.distances.size() + db.distances.size());
        pooled.assign(da.distances.begin(), da.distances.end());
        pooled.insert(pooled.end(), db.distances.begin(), db.distances.end());
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

Result<MaskEngine> makeMaskEngine(Options options) {
    options.perPointDistances = true;
    options.directedOnly = true;
    Result<Engine> engine = Engine::create(options);
    if (!engine) return engine.error();
    MaskEngine m{std::move(*engine), nullptr};
    if (m.engine.backend() != Backend::kCpu) {
        auto pass = masks_gpu::BoundaryPass::create(options.deviceIndex, options.validation);
        if (!pass) return pass.error();
        m.boundaryPass = std::move(*pass);
    }
    return m;
}

Result<MaskResult> compareMasks(MaskEngine& maskEngine, const Volume& a, LabelSelect selectA, const Volume& b,
                                LabelSelect selectB, const MaskOptions& options) {
    const auto start = Clock::now();
    if (auto e = checkInputs(a, b, options)) return *e;
    Engine& engine = maskEngine.engine;
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

    const auto t0 = Clock::now();
    masks_gpu::BoundaryPass* pass = options.hostExtraction ? nullptr : maskEngine.boundaryPass.get();
    Result<std::vector<detail::Extraction>> extracted =
        extractBoth(pass, {detail::MaskRef{&a, selectA}, detail::MaskRef{&b, selectB}}, itk ? 6 : conn,
                    threads, r.extraction);
    if (!extracted) return extracted.error();
    const detail::Extraction* ea = &(*extracted)[0];
    const detail::Extraction* eb = &(*extracted)[1];
    r.extractMs = msSince(t0);
    if (ea->count == 0 || eb->count == 0) {
        setEmpty(ea->count, eb->count, itk ? 0 : options.percentiles.size(), r);
        r.totalMs = msSince(start);
        return r;
    }
    Result<std::array<Direction, 2>> both =
        itk ? itkDirections(engine, a, selectA, *ea, b, selectB, *eb, threads, r)
            : bothDirections(engine, a, ea->boundary, b, eb->boundary, world, threads, r);
    if (!both) return both.error();
    Direction* ab = &(*both)[0];
    Direction* ba = &(*both)[1];
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
