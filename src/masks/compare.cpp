// Mask comparison in a named convention (rthdist/masks.hpp has the
// definitions, rthdist/mask_conventions.hpp each convention's rules and
// docs/masks.md the peers' sources they were read from).
//
// Both directions run on the exact engine with per-point distances: the
// boundary conventions in one call (both boundaries uploaded and indexed
// once; a voxel on both boundaries comes back at distance 0). itk sends less:
// a voxel of X inside Y has distance 0 while the nearest voxel of Y to any
// voxel outside Y is one of Y's 6-connected boundary voxels (a step from an
// interior voxel towards the query along its largest axis gets closer and
// stays in Y), so each direction queries X's voxels outside Y against Y's
// boundary; the zeros still count in every mean. Every convention searches
// both directions in A's frame (voxel_metric.hpp). The numbers made of the
// two directions are directions.cpp's; the deepmind convention (surfels with
// areas) lives in deepmind.cpp.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

#include "masks/boundary.hpp"
#include "masks/deepmind.hpp"
#include "masks/directions.hpp"
#include "masks/gpu_boundary.hpp"
#include "masks/per_point_call.hpp"
#include "masks/voxel_metric.hpp"
#include "masks_gpu/boundary_pass.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

using detail::Clock;
using detail::Direction;
using detail::msSince;

// Boundary conventions: both directions in one engine call (each set
// uploaded and indexed once), every boundary voxel a query (a voxel on both
// boundaries comes back at distance 0), each direction's numbers computed as
// the engine hands it back (directionsOfOneCall). Both sets take A's grid
// (B's equals it: checkSameGrid); `timed` gains the extraction, distance and
// engine times.
Result<std::array<Direction, 2>> bothDirections(Engine& engine, const Volume& a, std::span<const uint64_t> ba,
                                                const Volume& b, std::span<const uint64_t> bb,
                                                const MaskOptions& options, MaskResult& timed) {
    const auto t0 = Clock::now();
    const detail::VoxelMetric metric(a, conventionRules(options.convention).metric == Metric::kWorld);
    const detail::SearchPoints pa = metric.searchPoints(ba, options.threads);
    const detail::SearchPoints pb = metric.searchPoints(bb, options.threads);
    timed.extractMs += msSince(t0);
    const detail::PairCall call = [&](const CallOptions& c) {
        return engine.compute(PointView(pa), PointView(pb), c);
    };
    return detail::directionsOfOneCall(engine, call, metric,
                                       {detail::Side{&a, ba, bb}, detail::Side{&b, bb, ba}}, options, timed);
}

// The checks of compareMasks that every convention shares.
std::optional<Error> checkInputs(const Volume& a, const Volume& b, const MaskOptions& options) {
    if (auto e = checkVolume(a)) return e;
    if (auto e = checkVolume(b)) return e;
    if (auto e = checkSameGrid(a, b)) return e;
    return detail::checkOptions(options);
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

// itk (PointSet::kForeground): each direction its own call (X's voxels
// outside Y against Y's boundary), both in A's frame of the convention's metric.
Result<std::array<Direction, 2>> itkDirections(Engine& engine, const Volume& a, LabelSelect selectA,
                                               const detail::Extraction& ea, const Volume& b,
                                               LabelSelect selectB, const detail::Extraction& eb, bool world,
                                               int threads, MaskResult& r) {
    const auto t0 = Clock::now();
    const std::array<DirectionPoints, 2> p = itkPoints(a, selectA, ea.count, b, selectB, eb.count, threads);
    r.extractMs += msSince(t0);
    const detail::VoxelMetric metric(a, world);
    Result<Direction> ab =
        detail::directed(metric, a, p[0].queries, p[0].zeros, p[0].zeroWitness, eb.boundary,
                         detail::oneShotCall(engine, metric, eb.boundary, threads, r), threads, r);
    if (!ab) return ab.error();
    Result<Direction> ba =
        detail::directed(metric, b, p[1].queries, p[1].zeros, p[1].zeroWitness, ea.boundary,
                         detail::oneShotCall(engine, metric, ea.boundary, threads, r), threads, r);
    if (!ba) return ba.error();
    return std::array<Direction, 2>{std::move(*ab), std::move(*ba)};
}

}  // namespace

const char* conventionName(Convention c) {
    return size_t(c) < kConventionRules.size() ? conventionRules(c).name : "?";
}

const char* conventionRule(Convention c) {
    return size_t(c) < kConventionRules.size() ? conventionRules(c).rule : "?";
}

bool parseConvention(const std::string& text, Convention& out) {
    for (const ConventionRules& row : kConventionRules) {
        if (text == row.name) {
            out = row.convention;
            return true;
        }
    }
    return false;
}

std::string conventionNames() {
    std::string names;
    for (const ConventionRules& row : kConventionRules)
        names += (names.empty() ? "" : ", ") + std::string(row.name);
    return names;
}

const char* pointSetName(PointSet p) {
    switch (p) {
        case PointSet::kBoundary: return "boundary_voxels";
        case PointSet::kForeground: return "voxels";
        case PointSet::kSurfels: return "surfels";
    }
    return "?";
}

const char* metricName(Metric m) { return m == Metric::kWorld ? "world" : "spacing"; }

const char* emptyStatusName(EmptyStatus s) {
    switch (s) {
        case EmptyStatus::kNone: return "ok";
        case EmptyStatus::kBothEmpty: return "both_empty";
        case EmptyStatus::kAEmpty: return "a_empty";
        case EmptyStatus::kBEmpty: return "b_empty";
    }
    return "?";
}

Result<MaskEngine> makeMaskEngine(Options options, bool devicePass) {
    options.perPointDistances = true;
    options.directedOnly = true;
    Result<Engine> engine = Engine::create(options);
    if (!engine) return engine.error();
    MaskEngine m{std::move(*engine), nullptr};
    if (devicePass && m.engine.backend() != Backend::kCpu) {
        auto pass = masks_gpu::BoundaryPass::create(options.deviceIndex, options.validation);
        if (!pass) return pass.error();
        m.boundaryPass = std::move(*pass);
    }
    return m;
}

Backend oneShotMaskBackend(const Options& options, const Volume& a, const Volume& b,
                           const std::vector<Convention>& conventions) {
    const uint64_t voxels = nonzeroVoxels(a) + nonzeroVoxels(b);
    uint64_t points = 0;
    for (Convention c : conventions)
        points += voxels * (conventionRules(c).points == PointSet::kSurfels ? 8 : 1);
    return oneShotBackendFor(points, options);
}

Result<MaskResult> compareMasks(MaskEngine& maskEngine, const Volume& a, LabelSelect selectA, const Volume& b,
                                LabelSelect selectB, const MaskOptions& options) {
    const auto start = Clock::now();
    if (auto e = checkInputs(a, b, options)) return *e;
    Engine& engine = maskEngine.engine;
    const Convention c = options.convention;
    const ConventionRules& rules = conventionRules(c);
    if (rules.points == PointSet::kSurfels)
        return detail::compareDeepmind(engine, a, selectA, b, selectB, options);
    const int conn = detail::connectivityOf(c, options.connectivity);
    // Foreground conventions (itk): every voxel a point; the boundary serves the search (above).
    const bool itk = rules.points == PointSet::kForeground;
    MaskResult r;
    r.convention = c;
    r.connectivity = itk ? 0 : conn;
    r.percentiles = options.percentiles;
    const int threads = options.threads;

    const auto t0 = Clock::now();
    masks_gpu::BoundaryPass* pass = options.hostExtraction ? nullptr : maskEngine.boundaryPass.get();
    const std::array<detail::MaskRef, 2> masks{detail::MaskRef{&a, selectA}, detail::MaskRef{&b, selectB}};
    Result<std::vector<detail::Extraction>> extracted =
        detail::extractBoundaries(pass, masks, itk ? 6 : conn, threads, r.extraction);
    if (!extracted) return extracted.error();
    const detail::Extraction* ea = &(*extracted)[0];
    const detail::Extraction* eb = &(*extracted)[1];
    r.extractMs = msSince(t0);
    if (ea->count == 0 || eb->count == 0) {
        detail::setEmpty(itk ? ea->count : ea->boundary.size(), itk ? eb->count : eb->boundary.size(),
                         options.percentiles, r);
        r.totalMs = msSince(start);
        return r;
    }
    Result<std::array<Direction, 2>> both =
        itk ? itkDirections(engine, a, selectA, *ea, b, selectB, *eb, rules.metric == Metric::kWorld, threads,
                            r)
            : bothDirections(engine, a, ea->boundary, b, eb->boundary, options, r);
    if (!both) return both.error();
    detail::combine(options, (*both)[0], (*both)[1], r);
    r.totalMs = msSince(start);
    return r;
}

}  // namespace rthdist::masks
