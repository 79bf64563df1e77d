// A reference prepared once (rthdist/masks.hpp, PreparedReference): the reference's side
// of every convention is extracted and indexed here, and each comparison
// does the prediction's side and the same arithmetic as compareMasks
// (directions.hpp, deepmind.hpp).

#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "masks/boundary.hpp"
#include "masks/deepmind.hpp"
#include "masks/directions.hpp"
#include "masks/gpu_boundary.hpp"
#include "masks/per_point_call.hpp"
#include "masks/selection_bits.hpp"
#include "masks/surfels.hpp"
#include "masks/voxel_metric.hpp"
#include "masks_gpu/boundary_pass.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {

struct PreparedReference::State {
    Volume grid;  // the reference without its labels
    LabelSelect select;
    Convention convention = Convention::kRthdist;
    int connectivity = 6;          // of the boundary (itk: 6; deepmind: unused)
    detail::Extraction extracted;  // boundary conventions and itk: count and boundary voxels
    detail::SelectionBits bits;    // itk
    detail::Surfels surfels;       // deepmind
    std::optional<PreparedSet> set;
    double prepareMs = 0.0;
    std::string extraction = "host";
};

namespace {

using detail::Clock;
using detail::Direction;
using detail::msSince;
using State = PreparedReference::State;

PointSet kindOf(Convention c) { return conventionRules(c).points; }
bool worldMetric(Convention c) { return conventionRules(c).metric == Metric::kWorld; }

// The frame both directions search in: the reference's (A's) grid.
detail::VoxelMetric metricOf(const State& s) {
    return kindOf(s.convention) == PointSet::kSurfels
               ? detail::VoxelMetric::corners(s.grid)
               : detail::VoxelMetric(s.grid, worldMetric(s.convention));
}

std::string pointsText(Convention c, int connectivity) {
    switch (kindOf(c)) {
        case PointSet::kForeground: return "all foreground voxels";
        case PointSet::kSurfels: return "surfels";
        case PointSet::kBoundary: break;
    }
    return std::to_string(connectivity) + "-connected boundary voxels in the " +
           metricName(conventionRules(c).metric) + " metric";
}

// Empty when `options` measure the point set the reference was prepared with.
std::optional<Error> checkPreparedFor(const State& s, const MaskOptions& options) {
    const Convention c = options.convention;
    const int conn = detail::connectivityOf(c, options.connectivity);
    const bool same = kindOf(c) == kindOf(s.convention) &&
                      (kindOf(c) != PointSet::kBoundary ||
                       (conn == s.connectivity && worldMetric(c) == worldMetric(s.convention)));
    if (same) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument,
                 std::string("masks: the reference ") + s.grid.path + " was prepared for convention '" +
                     conventionName(s.convention) + "' (" + pointsText(s.convention, s.connectivity) +
                     "); convention '" + conventionName(c) + "' needs " + pointsText(c, conn) +
                     ": prepare the reference for it"};
}

// Prepares `points` (voxels or corners of the reference) in the search frame.
Result<PreparedSet> prepareSet(Engine& engine, const detail::VoxelMetric& metric,
                               std::span<const uint64_t> points, int threads) {
    const detail::SearchPoints p = metric.searchPoints(points, threads);
    return engine.prepare(PointView(p));
}

// Searches float queries against the reference's prepared set.
detail::NearestCall againstReference(Engine& engine, const PreparedSet& reference) {
    return [&engine, &reference](std::span<const glm::vec3> q) -> Result<HausdorffResult> {
        Result<PreparedSet> queries = engine.prepare(PointView(q));
        if (!queries) return queries.error();
        return engine.compute(*queries, reference, detail::perPointCall(true));
    };
}

// The prediction's boundary (one mask through extractBoundaries).
Result<detail::Extraction> extractOne(MaskEngine& engine, const Volume& v, LabelSelect select,
                                      int connectivity, const MaskOptions& options, std::string& where) {
    masks_gpu::BoundaryPass* pass = options.hostExtraction ? nullptr : engine.boundaryPass.get();
    const detail::MaskRef mask{&v, select};
    Result<std::vector<detail::Extraction>> e =
        detail::extractBoundaries(pass, std::span(&mask, 1), connectivity, options.threads, where);
    if (!e) return e.error();
    return std::move(e->front());
}

// rthdist, monai, medpy, plastimatch: the prediction's boundary prepared,
// both directions in one call on the two prepared sets.
Result<std::array<Direction, 2>> boundaryDirections(Engine& engine, const State& s, const Volume& b,
                                                    const detail::Extraction& eb, const MaskOptions& options,
                                                    MaskResult& r) {
    const auto t0 = Clock::now();
    const detail::VoxelMetric metric = metricOf(s);
    const detail::SearchPoints pb = metric.searchPoints(eb.boundary, options.threads);
    r.extractMs += msSince(t0);
    const detail::PairCall call = [&](const CallOptions& c) -> Result<HausdorffResult> {
        Result<PreparedSet> prediction = engine.prepare(PointView(pb));
        if (!prediction) return prediction.error();
        return engine.compute(*s.set, *prediction, c);
    };
    const std::span<const uint64_t> ba = s.extracted.boundary;
    return detail::directionsOfOneCall(
        engine, call, metric, {detail::Side{&s.grid, ba, eb.boundary}, detail::Side{&b, eb.boundary, ba}},
        options, r);
}

// itk: the reference's voxels outside the prediction query the prediction's
// boundary (one-shot); the prediction's voxels outside the reference query
// the reference's prepared boundary.
Result<std::array<Direction, 2>> itkDirections(Engine& engine, const State& s, const Volume& b,
                                               LabelSelect sb, const detail::Extraction& eb, int threads,
                                               MaskResult& r) {
    const auto t0 = Clock::now();
    const std::vector<uint64_t> outsideB = s.bits.minus(b, sb, threads);
    const std::vector<uint64_t> outsideA = s.bits.missingFrom(b, sb, threads);
    const uint64_t zerosA = s.extracted.count - outsideB.size(), zerosB = eb.count - outsideA.size();
    const uint64_t zeroWitness = zerosA > 0 || zerosB > 0 ? s.bits.firstCommon(b, sb).value_or(0) : 0;
    r.extractMs += msSince(t0);
    const detail::VoxelMetric metric = metricOf(s);
    Result<Direction> ab =
        detail::directed(metric, s.grid, outsideB, zerosA, zeroWitness, eb.boundary,
                         detail::oneShotCall(engine, metric, eb.boundary, threads, r), threads, r);
    if (!ab) return ab.error();
    Result<Direction> ba = detail::directed(metric, b, outsideA, zerosB, zeroWitness, s.extracted.boundary,
                                            againstReference(engine, *s.set), threads, r);
    if (!ba) return ba.error();
    return std::array<Direction, 2>{std::move(*ab), std::move(*ba)};
}

// Every convention but deepmind.
Result<MaskResult> compareVoxels(MaskEngine& engine, const State& s, const Volume& b, LabelSelect sb,
                                 const MaskOptions& options, Clock::time_point start) {
    const bool itk = kindOf(options.convention) == PointSet::kForeground;
    MaskResult r;
    r.convention = options.convention;
    r.connectivity = itk ? 0 : s.connectivity;
    r.percentiles = options.percentiles;
    const auto t0 = Clock::now();
    Result<detail::Extraction> eb = extractOne(engine, b, sb, s.connectivity, options, r.extraction);
    if (!eb) return eb.error();
    r.extractMs = msSince(t0);
    if (s.extracted.count == 0 || eb->count == 0) {
        detail::setEmpty(itk ? s.extracted.count : s.extracted.boundary.size(),
                         itk ? eb->count : eb->boundary.size(), options.percentiles, r);
        r.totalMs = msSince(start);
        return r;
    }
    Result<std::array<Direction, 2>> both =
        itk ? itkDirections(engine.engine, s, b, sb, *eb, options.threads, r)
            : boundaryDirections(engine.engine, s, b, *eb, options, r);
    if (!both) return both.error();
    detail::combine(options, (*both)[0], (*both)[1], r);
    r.totalMs = msSince(start);
    return r;
}

// The reference's side of its convention, into `s`.
std::optional<Error> extractReference(MaskEngine& engine, const Volume& ref, const MaskOptions& options,
                                      State& s) {
    const int threads = options.threads;
    if (kindOf(s.convention) == PointSet::kSurfels) {
        s.surfels = detail::extractSurfels(ref, s.select, threads);
        return std::nullopt;  // no prepared set: see the header
    } else {
        Result<detail::Extraction> e =
            extractOne(engine, ref, s.select, s.connectivity, options, s.extraction);
        if (!e) return e.error();
        s.extracted = std::move(*e);
        if (s.extracted.count == 0) return std::nullopt;
        if (kindOf(s.convention) == PointSet::kForeground)
            s.bits = detail::SelectionBits(ref, s.select, threads);
    }
    Result<PreparedSet> set = prepareSet(engine.engine, metricOf(s), s.extracted.boundary, threads);
    if (!set) return set.error();
    s.set = std::move(*set);
    return std::nullopt;
}

}  // namespace

PreparedReference::PreparedReference(std::shared_ptr<const State> state) : m_state(std::move(state)) {}

const Volume& PreparedReference::grid() const { return m_state->grid; }
LabelSelect PreparedReference::select() const { return m_state->select; }
Convention PreparedReference::convention() const { return m_state->convention; }
int PreparedReference::connectivity() const {
    return kindOf(m_state->convention) == PointSet::kBoundary ? m_state->connectivity : 0;
}
uint64_t PreparedReference::selectedVoxels() const {
    return kindOf(m_state->convention) == PointSet::kSurfels ? m_state->surfels.selected
                                                             : m_state->extracted.count;
}
uint64_t PreparedReference::points() const {
    switch (kindOf(m_state->convention)) {
        case PointSet::kForeground: return m_state->extracted.count;
        case PointSet::kSurfels: return m_state->surfels.corners.size();
        case PointSet::kBoundary: break;
    }
    return m_state->extracted.boundary.size();
}
uint64_t PreparedReference::hostBytes() const {
    const State& s = *m_state;
    return s.extracted.boundary.capacity() * sizeof(uint64_t) +
           s.surfels.corners.capacity() * sizeof(uint64_t) + s.surfels.codes.capacity() + s.bits.bytes() +
           (s.set ? s.set->hostBytes() : 0);
}
uint64_t PreparedReference::deviceBytes() const { return m_state->set ? m_state->set->deviceBytes() : 0; }
double PreparedReference::prepareMs() const { return m_state->prepareMs; }
const std::string& PreparedReference::extraction() const { return m_state->extraction; }

Result<PreparedReference> prepareReference(MaskEngine& engine, const Volume& reference, LabelSelect select,
                                           const MaskOptions& options) {
    const auto start = Clock::now();
    if (auto e = checkVolume(reference)) return *e;
    if (auto e = detail::checkOptions(options)) return *e;
    auto s = std::make_shared<State>();
    s->grid.path = reference.path;
    s->grid.dims = reference.dims;
    s->grid.voxelToWorld = reference.voxelToWorld;
    s->grid.transform = reference.transform;
    s->select = select;
    s->convention = options.convention;
    s->connectivity = kindOf(options.convention) == PointSet::kBoundary
                          ? detail::connectivityOf(options.convention, options.connectivity)
                          : 6;
    if (auto e = extractReference(engine, reference, options, *s)) return *e;
    s->prepareMs = msSince(start);
    return PreparedReference(std::move(s));
}

Result<MaskResult> compareMasks(MaskEngine& engine, const PreparedReference& reference,
                                const Volume& prediction, LabelSelect select, const MaskOptions& options) {
    const auto start = Clock::now();
    const State& s = *reference.m_state;
    if (auto e = checkVolume(prediction)) return *e;
    if (auto e = checkSameGrid(s.grid, prediction)) return *e;
    if (auto e = detail::checkOptions(options)) return *e;
    if (auto e = checkPreparedFor(s, options)) return *e;
    if (kindOf(options.convention) != PointSet::kSurfels)
        return compareVoxels(engine, s, prediction, select, options, start);
    const auto t0 = Clock::now();
    const detail::Surfels sb = detail::extractSurfels(prediction, select, options.threads);
    return detail::compareSurfels(engine.engine, s.grid, s.surfels, prediction, sb, options, nullptr,
                                  msSince(t0), start);
}

}  // namespace rthdist::masks
