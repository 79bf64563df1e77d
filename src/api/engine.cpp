// Public entry of rthdist: input validation, the frame, and the Engine that
// keeps its backend (api/backend.hpp: the CPU one, or a Vulkan device and its
// pipelines) between calls. Each call asks the route planner
// (api/route_planner.hpp) how it runs and runs that route through the
// backend interface; the frame is entered and left here.
#include "rthdist/rthdist.hpp"
#include "rthdist/surface.hpp"
#include "rthdist/version.hpp"
#include "rthdist/vulkan_interop.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "api/backend.hpp"
#include "api/certify.hpp"
#include "api/device_views.hpp"
#include "api/narrowed_targets.hpp"
#include "api/out_of_core.hpp"
#include "api/route_planner.hpp"
#include "api/surface_engine.hpp"
#include "core/index_space.hpp"
#include "core/input_frame.hpp"
#include "core/input_limits.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"
#include "core/thread_pool.hpp"
#include "core/timings.hpp"
#include "cpu/exact_nearest.hpp"

namespace rthdist {

const char* versionString() { return RTHDIST_VERSION_STRING; }

namespace {

std::optional<Error> validateEngineOptions(const EngineOptions& o) {
    if (o.threads < 0) return Error{ErrorCode::kInvalidArgument, "threads must be >= 0"};
    if (o.devices.size() > kMaxEngineDevices)
        return Error{ErrorCode::kInvalidArgument,
                     "devices lists " + std::to_string(o.devices.size()) + " devices; at most " +
                         std::to_string(kMaxEngineDevices) + " (kMaxEngineDevices)"};
    for (int d : o.devices) {
        if (d < 0) return Error{ErrorCode::kInvalidArgument, "devices must be device indices >= 0"};
    }
    return std::nullopt;
}

std::optional<Error> validateBits(int bits) {
    if (bits < 0 || bits > core::kMaxBits) {
        return Error{ErrorCode::kInvalidArgument,
                     "bits must be 0 (auto) or 1.." + std::to_string(core::kMaxBits)};
    }
    return std::nullopt;
}

std::optional<Error> validateCallOptions(const CallOptions& o) {
    if (auto e = validateBits(o.bits)) return e;
    if (!(o.radiusGrowth > 1.0f) || !std::isfinite(o.radiusGrowth)) {
        return Error{ErrorCode::kInvalidArgument, "radiusGrowth must be a finite number > 1"};
    }
    if (o.perPointReady && !(o.perPointDistances && o.perPointNearestOnly))
        return Error{ErrorCode::kInvalidArgument,
                     "perPointReady hands back per-point nearest points: it needs perPointDistances and "
                     "perPointNearestOnly"};
    return std::nullopt;
}

// Per-point output holds 32-bit indices (PerPoint::nearest): both sets below
// 2^32 points. Checked before any pass over the points.
std::optional<Error> validatePerPointSizes(const PointView& a, const PointView& b, const CallOptions& call) {
    if (!call.perPointDistances || (a.count <= UINT32_MAX && b.count <= UINT32_MAX)) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument,
                 "per-point output (perPointDistances) holds 32-bit indices: sets of up to 2^32 - 1 points, "
                 "not " +
                     std::to_string(std::max(a.count, b.count))};
}

// A prepared set is one backend call's set: not split, so within api::kMaxCallPoints.
std::optional<Error> validatePreparedSize(const PointView& points) {
    if (points.count <= api::kMaxCallPoints) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument,
                 "a prepared set holds at most 2^31 - 1 points (it is not split into pieces), not " +
                     std::to_string(points.count) + ": compute it one-shot (Engine::compute of point views)"};
}

using core::msSince;

}  // namespace

struct Engine::Impl {
    EngineOptions options;
    CallOptions callDefaults;  // compute(a, b) without call options
    // Never null; shared with the sets it prepared (their buffers must be
    // destroyed before it), which it identifies.
    std::shared_ptr<api::ComputeBackend> backend;
    double setupMs = 0.0;
    uint64_t preparedCount = 0;
    cpu::KeptSurfaceTree surfaceTree;  // the CPU route's last mesh and its BVH
    api::KeptGpuSurface gpuSurface;    // the GPU route's last mesh and its framed corners
    SurfacePerPoint spareSurface;      // a recycled surface result's arrays (Engine::recycle)
};

struct PreparedSet::Impl {
    std::shared_ptr<api::ComputeBackend> backend;  // keeps it alive; first member, destroyed last
    core::SetSummary summary;
    glm::dvec3 origin{0.0};
    std::vector<glm::vec3> floats;      // p - origin rounded: what the backend searches
    std::vector<glm::dvec3> originals;  // the input when it is not float-exact
    bool doubleInput = false;           // given as doubles (per-point entries exact: makePerPointExact)
    double ownScale = 1.0;              // core::exactScale of `floats` alone
    std::shared_ptr<api::BackendSet> set;
    size_t count = 0;
    // Prepared from a device view: no host copy of its points (floats and
    // originals empty); its witnesses come from its device copy.
    bool onDevice = false;

    // The input as given (for witnesses in double and for the union frame).
    [[nodiscard]] PointView input() const {
        return originals.empty() ? PointView(std::span<const glm::vec3>(floats))
                                 : PointView(std::span<const glm::dvec3>(originals));
    }
};

PreparedSet::PreparedSet(std::shared_ptr<Impl> impl) : m_impl(std::move(impl)) {}
PreparedSet::PreparedSet(const PreparedSet&) = default;
PreparedSet& PreparedSet::operator=(const PreparedSet&) = default;
PreparedSet::PreparedSet(PreparedSet&&) noexcept = default;
PreparedSet& PreparedSet::operator=(PreparedSet&&) noexcept = default;
PreparedSet::~PreparedSet() = default;

size_t PreparedSet::size() const { return m_impl->count; }
glm::dvec3 PreparedSet::origin() const { return m_impl->origin; }
int PreparedSet::bits() const { return m_impl->set->bits(); }
uint64_t PreparedSet::deviceBytes() const { return m_impl->set->deviceBytes(); }
uint64_t PreparedSet::hostBytes() const {
    return m_impl->floats.capacity() * sizeof(glm::vec3) + m_impl->originals.capacity() * sizeof(glm::dvec3) +
           m_impl->set->hostBytes();
}

Engine::Engine(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Engine::Engine(Engine&&) noexcept = default;
Engine& Engine::operator=(Engine&&) noexcept = default;
Engine::~Engine() = default;

namespace {

// The engine's tuning: the caller's, else the environment's (the one read of
// it, rthdist/tuning.hpp); the worker pool's polling is process-wide.
void settleTuning(EngineOptions& options) {
    if (!options.tuning) options.tuning = tuningFromEnvironment();
    if (options.tuning->poolSpinMicros)
        core::setPoolSpin(std::chrono::microseconds(*options.tuning->poolSpinMicros));
}

}  // namespace

namespace {

// An Engine's state on its backend (api::openBackend); `borrowed`: the embedder's device.
Result<std::unique_ptr<Engine::Impl>> createImpl(const EngineOptions& given, const VulkanDevice* borrowed) {
    if (auto err = validateEngineOptions(given)) return *err;
    auto t0 = std::chrono::steady_clock::now();
    auto impl = std::make_unique<Engine::Impl>();
    impl->options = given;
    if (borrowed) impl->options.devices.clear();
    if (!impl->options.devices.empty()) impl->options.deviceIndex = impl->options.devices.front();
    settleTuning(impl->options);
    Result<std::unique_ptr<api::ComputeBackend>> backend = api::openBackend(impl->options, borrowed);
    if (!backend) return backend.error();
    impl->backend = std::move(backend.value());
    impl->setupMs = msSince(t0);
    return impl;
}

}  // namespace

Result<Engine> Engine::create(const EngineOptions& given) {
    Result<std::unique_ptr<Impl>> impl = createImpl(given, nullptr);
    if (!impl) return impl.error();
    return Engine(std::move(impl.value()));
}

Result<Engine> Engine::create(const Options& options) {
    if (auto err = validateCallOptions(options)) return *err;
    Result<Engine> engine = create(static_cast<const EngineOptions&>(options));
    if (engine) engine->m_impl->callDefaults = static_cast<const CallOptions&>(options);
    return engine;
}

Result<Engine> Engine::create(const VulkanDevice& device, const EngineOptions& given) {
    Result<std::unique_ptr<Impl>> impl = createImpl(given, &device);
    if (!impl) return impl.error();
    return Engine(std::move(impl.value()));
}

const std::string& Engine::deviceName() const { return m_impl->backend->deviceName(); }
Backend Engine::backend() const { return m_impl->backend->kind(); }
std::string Engine::pipelineCachePath() const { return m_impl->backend->pipelineCachePath(); }
std::string Engine::pipelineCacheStatus() const { return m_impl->backend->pipelineCacheStatus(); }

namespace {

// The computation: one pass per set checks the coordinates and takes its box
// (input_frame.hpp); the backends search float32 sets (shifted when an input
// is double); witnesses and distances come back in the original coordinates.
struct CheckedInputs {
    core::SetSummary a, b;
    // Either set was given as doubles though its view here is float (a
    // float-exact prepared set indexed again: kReframe): per-point entries
    // are made exact as for double views.
    bool givenAsDoubles = false;
};

Result<CheckedInputs> checkInputs(const PointView& a, const PointView& b, int threads) {
    Result<core::SetSummary> sa = core::summarizeSet(a, "A", threads);
    if (!sa) return sa.error();
    Result<core::SetSummary> sb = core::summarizeSet(b, "B", threads);
    if (!sb) return sb.error();
    return CheckedInputs{*sa, *sb};
}

// CallOptions::perPointReady for each direction of a complete result that
// the backend did not hand back early itself (ComputeBackend::handedBack).
void handBackTheRest(const Engine::Impl& impl, const HausdorffResult& r, const CallOptions& call) {
    if (!call.perPointReady) return;
    const uint32_t done = impl.backend->handedBack();
    if ((done & 1u) == 0) call.perPointReady(0, r.aNearest.nearest);
    if (!r.directedOnly && (done & 2u) == 0) call.perPointReady(1, r.bNearest.nearest);
}

// What every call's result carries besides the backend's figures; a
// nearest-only per-point call's distances dropped (the backends that
// computed them anyway: CallOptions::perPointNearestOnly).
void finishResult(Engine::Impl& impl, HausdorffResult& r, const CallOptions& call,
                  std::chrono::steady_clock::time_point t0) {
    if (call.perPointDistances && call.perPointNearestOnly) {
        r.aNearest.distance.clear();
        r.bNearest.distance.clear();
    }
    handBackTheRest(impl, r, call);
    r.timings.setup = impl.setupMs;
    impl.setupMs = 0.0;  // only the first call pays for creation
    r.timings.total = msSince(t0);
    r.validationMessages = impl.backend->validationMessages();
}

// Every per-point entry made the exact one in the caller's coordinates
// (cpu/exact_nearest.hpp: the backends' entries are their float pairs,
// within 2e of it; README "Per-point distances"), its time counted as
// refinement; the witness's entry, proven by the certificate, must come out
// as it is (else kInternal).
std::optional<Error> makePerPointExact(HausdorffResult& r, const PointView& a, const PointView& b,
                                       int threads) {
    const auto start = core::Clock::now();
    const auto direction = [threads](Directed& d, PerPoint& pp, const PointView& q, const PointView& t,
                                     const char* name) -> std::optional<Error> {
        d.counters.perPointMended = cpu::makePerPointExact(pp, q, t, threads);
        if (pp.nearest.empty() || d.queryIndex >= pp.nearest.size()) return std::nullopt;
        const bool distanceAgrees = pp.distance.empty() || pp.distance[d.queryIndex] == d.distance;
        if (pp.nearest[d.queryIndex] == d.targetIndex && distanceAgrees) return std::nullopt;
        return Error{ErrorCode::kInternal,
                     std::string("per-point distances: the exact pass and the proof of ") + name +
                         " disagree on its witness's nearest point"};
    };
    if (auto err = direction(r.aToB, r.aNearest, a, b, "h(A,B)")) return err;
    if (!r.directedOnly)
        if (auto err = direction(r.bToA, r.bNearest, b, a, "h(B,A)")) return err;
    r.timings.refine += core::msSince(start);
    return std::nullopt;
}

// The pair's frame: where the backend searched it and how its result comes
// back to the caller's coordinates.
struct Frame {
    glm::dvec3 origin{0.0};
    // The inputs as given, for witnesses in double and the certificate; empty
    // views for device views (the host cannot read them).
    PointView a, b;
    bool restore = false;  // the backend searched copies: distances recomputed from a and b
    bool onHost = true;    // the host can read a and b (else the device's own proof stands)
    // Either set was given as doubles: per-point entries are made exact
    // (float-exact doubles too: their float search is a float32 input's,
    // whose pairs are only within a relative 2^-21).
    bool doubleInput = false;
};

// Leaves the frame: the one place a result returns to the caller's
// coordinates (core::restoreOriginal), is certified (certify.hpp) and finished.
std::optional<Error> leaveFrame(Engine::Impl& impl, HausdorffResult& r, const Frame& frame,
                                const CallOptions& call, std::chrono::steady_clock::time_point t0) {
    if (frame.restore) core::restoreOriginal(r, frame.a, frame.b, impl.options.threads);
    r.origin = frame.origin;
    if (auto err = api::settleCertificates(r, frame.a, frame.b, impl.options.threads, frame.onHost))
        return err;
    // Double inputs (README "Per-point distances"): their float pairs'
    // distances may be e, an absolute 2^-20 of the frame, off (a relative
    // ~2^-21 where they are float values searched as they are); float
    // inputs keep their pairs (within that relative bound, documented).
    if (call.perPointDistances && frame.onHost && frame.doubleInput)
        if (auto err = makePerPointExact(r, frame.a, frame.b, impl.options.threads)) return err;
    finishResult(impl, r, call, t0);
    return std::nullopt;
}

Result<HausdorffResult> finished(Engine::Impl& impl, Result<HausdorffResult> r, const Frame& frame,
                                 const CallOptions& call, std::chrono::steady_clock::time_point t0) {
    if (!r) return r;
    if (auto err = leaveFrame(impl, *r, frame, call, t0)) return *err;
    return r;
}

Error refusal(const api::Plan& plan) { return Error{plan.code, plan.reason}; }

// One backend call of a framed pair, on device `lane`: scanned whole or
// indexed, as the planner says (every piece of the pieces' routes too).
// `floor`: the pieces' round one (core/per_point_floor.hpp); a pair scanned
// whole searches every query to its end.
Result<HausdorffResult> runFramed(Engine::Impl& impl, int lane, std::span<const glm::vec3> a,
                                  std::span<const glm::vec3> b, double scale, const CallOptions& call,
                                  const core::PerPointFloor& floor = {}) {
    const api::Plan plan =
        api::planFramedCall(a.size(), b.size(), call, api::MemoryBudget{}, impl.backend->caps());
    return plan.route == api::Route::kSmallPairScan
               ? impl.backend->scanFramed(lane, a, b, scale, call)
               : impl.backend->computeFramed(lane, a, b, scale, call, floor);
}

// Route::kPieces and kSeveralDevices (out_of_core.hpp), over the backend's lanes.
Result<HausdorffResult> runInPieces(Engine::Impl& impl, std::span<const glm::vec3> a,
                                    std::span<const glm::vec3> b, double scale, const CallOptions& call,
                                    const api::MemoryBudget& pieces, const std::optional<core::Bounds>& box) {
    api::ComputeBackend& backend = *impl.backend;
    const std::function<void()> release = [&backend] { backend.releaseScratch(); };
    const api::DirectedCall directed =
        [&](int lane, std::span<const glm::vec3> q, std::span<const glm::vec3> t, const CallOptions& piece,
            const core::PerPointFloor& floor) { return runFramed(impl, lane, q, t, scale, piece, floor); };
    const api::RecycleCall recycle = [&backend](int lane, PerPoint&& a, PerPoint&& b) {
        backend.recyclePerPoint(lane, std::move(a), std::move(b));
    };
    release();
    Result<HausdorffResult> r = api::computeInPieces(
        a, b, scale, call, pieces, directed, release, backend.caps().lanes, impl.options.threads, recycle,
        impl.options.tuning && impl.options.tuning->traceSubmits, box);
    release();  // the pieces' scratch is no use to the next call
    if (!r) return r;
    r->backend = backend.kind();
    r->device = backend.deviceName();
    return r;
}

// A framed pair on the planner's route: one call (scanned whole or indexed;
// in pieces after a kOutOfMemory under the automatic budget), or pieces.
// `box`: both sets' box when the spans are the caller's points (for pieces).
Result<HausdorffResult> runWithinBudget(Engine::Impl& impl, std::span<const glm::vec3> a,
                                        std::span<const glm::vec3> b, double scale, const CallOptions& call,
                                        const std::optional<core::Bounds>& box) {
    const api::Plan plan =
        api::planFramedCall(a.size(), b.size(), call, impl.backend->memoryBudget(), impl.backend->caps());
    if (plan.route == api::Route::kSmallPairScan || plan.route == api::Route::kOneCall) {
        Result<HausdorffResult> r = runFramed(impl, 0, a, b, scale, call);
        if (r || r.error().code != ErrorCode::kOutOfMemory || !plan.piecesOnOutOfMemory) return r;
        // A direction already handed back (perPointReady) is not handed back again from pieces.
        if (impl.backend->handedBack() != 0) return r;
    }
    return runInPieces(impl, a, b, scale, call, plan.pieces, box);
}

Result<HausdorffResult> computeNarrowed(Engine::Impl& impl, const PointView& a, const PointView& b,
                                        const CheckedInputs& checked, const CallOptions& call,
                                        std::chrono::steady_clock::time_point t0,
                                        const api::PairNarrowing& narrowed, double narrowingMs);

Result<HausdorffResult> computeIngested(Engine::Impl& impl, const PointView& a, const PointView& b,
                                        const CallOptions& call, std::chrono::steady_clock::time_point t0,
                                        bool narrow = true);

// The route of a pair of host views (Engine::compute's and a narrowed
// pair's calls').
api::Plan planHostViews(const Engine::Impl& impl, const PointView& a, const PointView& b,
                        const CallOptions& call) {
    api::PairShape shape;
    shape.input = api::PairShape::Input::kHostViews;
    shape.a = a.count;
    shape.b = b.count;
    shape.packedFloat = a.packedFloat() && b.packedFloat();
    return api::planRoute(shape, call, impl.backend->memoryBudget(), impl.backend->caps());
}

// Whether strays of their own leave a pair whole (api::narrowPair's
// `ownStrays`): not for per-point output, nor on the GPU backends.
bool coresForOwnStrays(const Engine::Impl& impl, const CallOptions& call) {
    return call.perPointDistances || impl.backend->caps().coresForOwnStrays;
}

// Host views checked on the host: the frame entered (origin, float copies
// where needed, the exact scale), the pair run, the frame left. A pair that
// narrows (api/narrowed_targets.hpp) runs as computeNarrowed says unless
// `narrow` is false (the calls of computeNarrowed).
Result<HausdorffResult> computeViews(Engine::Impl& impl, const PointView& a, const PointView& b,
                                     const CheckedInputs& checked, const CallOptions& call,
                                     std::chrono::steady_clock::time_point t0, bool narrow = true) {
    if (auto err = validateCallOptions(call)) return *err;
    const glm::dvec3 origin = core::searchOrigin(checked.a, checked.b);
    if (auto err = core::checkPairFrame(a, checked.a.box, checked.a.floatExact, b, checked.b.box,
                                        checked.b.floatExact, origin))
        return *err;
    double narrowingMs = 0.0;  // looking for it (Timings::pieces), whether it narrows or not
    if (narrow) {
        const auto narrowStart = core::Clock::now();
        std::optional<api::PairNarrowing> narrowed =
            api::narrowPair(a, checked.a, b, checked.b, call.directedOnly, impl.options.threads,
                            coresForOwnStrays(impl, call));
        narrowingMs = core::msSince(narrowStart);
        if (narrowed) return computeNarrowed(impl, a, b, checked, call, t0, *narrowed, narrowingMs);
    }
    const core::FloatSet fa(a, origin, impl.options.threads), fb(b, origin, impl.options.threads);
    const double scale = core::exactScale(
        std::max(core::searchMagnitude(checked.a, origin), core::searchMagnitude(checked.b, origin)));
    const bool copied = fa.span().data() != a.data || fb.span().data() != b.data;
    // The spans are the caller's floats: the checked boxes are theirs.
    std::optional<core::Bounds> box;
    if (!copied) box = core::unite(checked.a.box, checked.b.box);
    Result<HausdorffResult> r = finished(
        impl, runWithinBudget(impl, fa.span(), fb.span(), scale, call, box),
        Frame{origin, a, b, copied, true,
              checked.givenAsDoubles || a.scalar == Scalar::kFloat64 || b.scalar == Scalar::kFloat64},
        call, t0);
    if (r) r->timings.pieces += narrowingMs;
    return r;
}

// One call of a narrowed pair (both cores, or a direction's core and kept
// targets) on the route Engine::compute takes for its shape, without
// looking for narrowing again: where BackendCaps::narrowedIngest (a GPU by
// default), packed float32 subsets go to the device ingest (the device
// converts them: the host staging of computeViews took ~2 of the 5 ms of a
// call of 2 x 200k points on an H200, the ingest ~0.3); else (a CPU device,
// lavapipe) to computeViews, which reuses the boxes the narrowing took
// (there the ingest's pass is host work too: 63 -> 80 ms on that pair on 2
// cores).
Result<HausdorffResult> computeNarrowedCall(Engine::Impl& impl, const PointView& a, const PointView& b,
                                            const CheckedInputs& checked, const CallOptions& call,
                                            std::chrono::steady_clock::time_point t0) {
    if (impl.backend->caps().narrowedIngest &&
        planHostViews(impl, a, b, call).route == api::Route::kDeviceIngest)
        return computeIngested(impl, a, b, call, t0, false);
    return computeViews(impl, a, b, checked, call, t0, false);
}

// A direction searched over subsets (queries `core` of q, targets `targets`
// of t), back in the inputs' indices (subsets keep input order, so the
// smallest index of a tie stays the smallest), with its stray queries
// against every target merged in: the larger value, on a tie the smaller
// query index (the brute force's rule); per-point entries scattered back in
// query order.
void mergeDirection(Directed& d, PerPoint& perPoint, const api::PointSubset& core,
                    const api::PointSubset& strays, const api::PointSubset& targets, const PointView& q,
                    const PointView& t, const CallOptions& call, int threads) {
    constexpr size_t kChunk = size_t(1) << 16;
    if (!targets.whole()) {
        d.targetIndex = targets.indexOf(d.targetIndex);
        if (d.certificate.confirmed) d.certificate.nearest = targets.indexOf(d.certificate.nearest);
        std::vector<uint32_t>& nearest = perPoint.nearest;
        core::parallelChunks(nearest.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
            for (size_t k = begin; k < end; ++k) nearest[k] = uint32_t(targets.indexOf(nearest[k]));
        });
        d.counters.narrowedTargets = targets.view.count;
    }
    if (core.whole()) return;
    // The stray queries against every target: a brute force in double on
    // the host (a few queries; exact without a certificate).
    PerPoint strayPoints;
    Directed x = api::strayQueries(strays, t, call.perPointDistances ? &strayPoints : nullptr, threads);
    if (!call.perPointDistances || call.perPointNearestOnly) strayPoints.distance.clear();
    d.queryIndex = core.indexOf(d.queryIndex);
    if (d.certificate.confirmed) d.certificate.query = core.indexOf(d.certificate.query);
    x.queryIndex = strays.indexOf(x.queryIndex);
    x.certificate.query = x.queryIndex;
    if (call.perPointDistances) {
        PerPoint whole;
        if (!perPoint.nearest.empty()) whole.nearest.resize(q.count);
        if (!perPoint.distance.empty()) whole.distance.resize(q.count);
        core::parallelChunks(core.view.count, kChunk, threads, [&](size_t begin, size_t end, int) {
            core.forIndices(begin, end, [&](uint64_t k, uint64_t i) {
                if (!perPoint.nearest.empty()) whole.nearest[i] = perPoint.nearest[k];
                if (!perPoint.distance.empty()) whole.distance[i] = perPoint.distance[k];
            });
        });
        for (size_t k = 0; k < strays.view.count; ++k) {
            if (!whole.nearest.empty()) whole.nearest[strays.listed[k]] = strayPoints.nearest[k];
            if (!whole.distance.empty()) whole.distance[strays.listed[k]] = strayPoints.distance[k];
        }
        perPoint = std::move(whole);
    }
    Directed winner =
        x.distance > d.distance || (x.distance == d.distance && x.queryIndex < d.queryIndex) ? x : d;
    winner.counters = d.counters;
    winner.counters.queries += x.counters.queries;  // the strays' brute force counts only its queries
    d = winner;
}

// A narrowed pair: one call on both cores (api::JointCores), or the two
// directions as directed calls, a narrowed direction over its kept targets
// (its own frame), the other over the whole set; each set's stray queries
// apart against every target; results merged back into the input's indices.
// Per-point arrays are handed back once both directions are done. The
// narrowing's host work (narrowingMs, the merges, the strays) is
// Timings::pieces.
Result<HausdorffResult> computeNarrowed(Engine::Impl& impl, const PointView& a, const PointView& b,
                                        const CheckedInputs& checked, const CallOptions& call,
                                        std::chrono::steady_clock::time_point t0,
                                        const api::PairNarrowing& narrowed, double narrowingMs) {
    const int threads = impl.options.threads;
    CallOptions sub = call;
    sub.perPointReady = nullptr;
    Result<HausdorffResult> r = Error{ErrorCode::kInternal, "narrowed pair not run"};
    if (narrowed.joint) {
        const api::JointCores& j = *narrowed.joint;
        r = computeNarrowedCall(impl, j.coreA.view, j.coreB.view, CheckedInputs{j.summaryA, j.summaryB}, sub,
                                t0);
        if (!r) return r;
        const auto mergeStart = core::Clock::now();
        mergeDirection(r->aToB, r->aNearest, j.coreA, j.straysA, j.coreB, a, b, call, threads);
        if (!call.directedOnly)
            mergeDirection(r->bToA, r->bNearest, j.coreB, j.straysB, j.coreA, b, a, call, threads);
        narrowingMs += core::msSince(mergeStart);
    } else {
        sub.directedOnly = true;
        auto one = [&](const PointView& q, const core::SetSummary& qSummary, const PointView& t,
                       const core::SetSummary& tSummary,
                       const std::optional<api::NarrowedTargets>& n) -> Result<HausdorffResult> {
            if (!n) return computeNarrowedCall(impl, q, t, CheckedInputs{qSummary, tSummary}, sub, t0);
            Result<HausdorffResult> d =
                computeNarrowedCall(impl, n->core.view, n->targets.view,
                                    CheckedInputs{n->coreSummary, n->targetsSummary}, sub, t0);
            if (!d) return d;
            const auto mergeStart = core::Clock::now();
            mergeDirection(d->aToB, d->aNearest, n->core, n->strays, n->targets, q, t, call, threads);
            narrowingMs += core::msSince(mergeStart);
            return d;
        };
        r = one(a, checked.a, b, checked.b, narrowed.targetsB);
        if (!r) return r;
        if (!call.directedOnly) {
            Result<HausdorffResult> ba = one(b, checked.b, a, checked.a, narrowed.targetsA);
            if (!ba) return ba.error();
            r->bToA = ba->aToB;
            r->bNearest = std::move(ba->aNearest);
            r->directedOnly = false;
            core::addStageTimings(r->timings, ba->timings);  // setup: the first call's alone
            r->timings.pieces += ba->timings.pieces;
            r->validationMessages += ba->validationMessages;
        }
    }
    r->hausdorff = call.directedOnly ? r->aToB.distance : std::max(r->aToB.distance, r->bToA.distance);
    r->timings.pieces += narrowingMs;
    r->timings.total = msSince(t0);
    if (call.perPointReady) {
        call.perPointReady(0, r->aNearest.nearest);
        if (!call.directedOnly) call.perPointReady(1, r->bNearest.nearest);
    }
    return r;
}

// Whether two prepared sets can be searched as they are: one frame, within
// the contract's bound, and one exact scale.
api::PairShape preparedShape(const Engine::Impl& impl, const PreparedSet::Impl& a,
                             const PreparedSet::Impl& b) {
    api::PairShape shape;
    shape.input = api::PairShape::Input::kPreparedSets;
    shape.a = a.count;
    shape.b = b.count;
    shape.sameEngine = a.backend == impl.backend && b.backend == impl.backend;
    shape.onDevice = a.onDevice || b.onDevice;
    shape.hostCopies = !a.originals.empty() || !b.originals.empty();
    shape.oneOrigin = a.origin == b.origin && core::frameKeepsBound(a.summary, b.summary, a.origin);
    const double pairScale = std::min(a.ownScale, b.ownScale);  // of the larger magnitude
    shape.oneScale = a.ownScale == pairScale && b.ownScale == pairScale;
    return shape;
}

// Two prepared sets' frame: their origin, their inputs.
Frame preparedFrame(const PreparedSet::Impl& a, const PreparedSet::Impl& b) {
    // Sets prepared from device views keep no host copy: their proof is the device's own.
    const bool onHost = !a.onDevice && !b.onDevice;
    return Frame{a.origin,
                 onHost ? a.input() : PointView{},
                 onHost ? b.input() : PointView{},
                 !a.originals.empty() || !b.originals.empty(),
                 onHost,
                 a.doubleInput || b.doubleInput};
}

}  // namespace

Result<HausdorffResult> Engine::compute(PointView a, PointView b) {
    return compute(a, b, m_impl->callDefaults);
}

namespace {

// A packed float view as the points it holds.
std::span<const glm::vec3> asVec3(const PointView& v) {
    return std::span<const glm::vec3>(static_cast<const glm::vec3*>(v.data), v.count);
}

// Whether a direction of a packed float pair could narrow, from the sets'
// bounds (as the device ingest found them): a set's own magnitude (origin
// 0 for float32 inputs), or its sampled core's (strays among its points),
// against the pair's; narrowTargets's first test.
bool mayNarrow(const core::Bounds& boxA, const core::Bounds& boxB, const PointView& a, const PointView& b,
               const CallOptions& call) {
    const double ma = core::largestMagnitude(boxA), mb = core::largestMagnitude(boxB);
    const double whole = std::max(ma, mb);
    auto gains = [whole](const PointView& q, double m) {
        return api::narrowingPays(whole, m) ||
               api::narrowingPays(whole, api::frameMagnitude(api::sampledCore(q, 256), true));
    };
    return gains(a, ma) || (!call.directedOnly && gains(b, mb));
}

// Route::kDeviceIngest: a one-shot call on packed float arrays: the device
// checks, bounds and samples the points; the host only copies them.
// Every pair looks for narrowed targets (route_planner.hpp): pairs of at
// most kNarrowCheckPoints points in all from boxes the host takes first
// where the backend says so (BackendCaps::narrowOnHost; the device then
// ingests only pairs that do not narrow), the others from the device's
// bounds: when the pair narrows, the device stops before its indexes, its
// upload thrown away (its wall reported as upload). Packed float32 views:
// float-exact summaries.
// `narrow` false: no look (the calls of computeNarrowed).
Result<HausdorffResult> computeIngested(Engine::Impl& impl, const PointView& a, const PointView& b,
                                        const CallOptions& call, std::chrono::steady_clock::time_point t0,
                                        bool narrow) {
    if (auto err = core::checkShape(a, "A")) return *err;
    if (auto err = core::checkShape(b, "B")) return *err;
    if (auto err = validateCallOptions(call)) return *err;
    std::optional<api::PairNarrowing> narrowed;
    std::optional<CheckedInputs> checked;
    double narrowingMs = 0.0;  // looking for it (Timings::pieces), whether it narrows or not
    std::function<bool(const core::Bounds&, const core::Bounds&)> leave;
    const bool check = narrow && !validatePerPointSizes(a, b, call);
    const int threads = impl.options.threads;
    if (check && impl.backend->caps().narrowOnHost && a.count + b.count <= api::kNarrowCheckPoints) {
        // The boxes on the host first; bad points are left to the ingest to report.
        const auto start = core::Clock::now();
        Result<CheckedInputs> boxes = checkInputs(a, b, threads);
        if (boxes && mayNarrow(boxes->a.box, boxes->b.box, a, b, call))
            narrowed = api::narrowPair(a, boxes->a, b, boxes->b, call.directedOnly, threads,
                                       coresForOwnStrays(impl, call));
        narrowingMs = core::msSince(start);
        if (narrowed) return computeNarrowed(impl, a, b, *boxes, call, t0, *narrowed, narrowingMs);
    } else if (check) {
        leave = [&](const core::Bounds& boxA, const core::Bounds& boxB) {
            if (!mayNarrow(boxA, boxB, a, b, call)) return false;
            const auto start = core::Clock::now();
            const CheckedInputs boxes{core::SetSummary{boxA, true}, core::SetSummary{boxB, true}};
            narrowed = api::narrowPair(a, boxes.a, b, boxes.b, call.directedOnly, threads,
                                       coresForOwnStrays(impl, call));
            narrowingMs = core::msSince(start);
            if (!narrowed) return false;
            checked = boxes;
            return true;
        };
    }
    const auto ingestStart = core::Clock::now();
    Result<HausdorffResult> r = impl.backend->computeIngested(asVec3(a), asVec3(b), call, leave);
    const double ingestMs = core::msSince(ingestStart) - narrowingMs;
    if (checked) {
        if (!r) return r;
        Result<HausdorffResult> n = computeNarrowed(impl, a, b, *checked, call, t0, *narrowed, narrowingMs);
        if (!n) return n;
        // The ingest the narrowed calls replaced, thrown away: its wall as
        // upload (its bounds included), its device times as they were.
        n->timings.upload += ingestMs;
        n->timings.gpuUpload += r->timings.gpuUpload;
        n->timings.gpuIndex += r->timings.gpuIndex;
        return n;
    }
    if (r) r->timings.pieces += narrowingMs;
    return finished(impl, std::move(r), Frame{glm::dvec3(0.0), a, b}, call, t0);
}

}  // namespace

Result<HausdorffResult> Engine::compute(PointView a, PointView b, const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    const api::Plan plan = planHostViews(*m_impl, a, b, call);
    if (plan.route == api::Route::kDeviceIngest) return computeIngested(*m_impl, a, b, call, t0);
    if (auto err = validatePerPointSizes(a, b, call)) return *err;
    Result<CheckedInputs> checked = checkInputs(a, b, m_impl->options.threads);
    if (!checked) return checked.error();
    return computeViews(*m_impl, a, b, *checked, call, t0);
}

Result<SurfaceResult> Engine::hausdorffToSurface(PointView points, MeshView surface) {
    return hausdorffToSurface(points, surface, SurfaceCallOptions{});
}

// Point to surface on the kept backend (api/surface_engine.hpp routes it).
Result<SurfaceResult> Engine::hausdorffToSurface(PointView points, MeshView surface,
                                                 const SurfaceCallOptions& call) {
    return api::surfaceOnEngine(*m_impl->backend, m_impl->options, m_impl->surfaceTree, m_impl->gpuSurface,
                                points, surface, call, m_impl->spareSurface);
}

void Engine::recycle(HausdorffResult&& spent) {
    m_impl->backend->recyclePerPoint(0, std::move(spent.aNearest), std::move(spent.bNearest));
}

void Engine::recycle(SurfaceResult&& spent) { m_impl->spareSurface = std::move(spent.perPoint); }

Result<PreparedSet> Engine::prepare(PointView points, const PrepareOptions& options) {
    if (auto err = validateBits(options.bits)) return *err;
    if (auto err = validatePreparedSize(points)) return *err;
    if (options.origin)
        if (auto err = core::checkOrigin(*options.origin, "PrepareOptions::origin")) return *err;
    Result<core::SetSummary> summary = core::summarizeSet(points, "to prepare", m_impl->options.threads);
    if (!summary) return summary.error();
    auto set = std::make_shared<PreparedSet::Impl>();
    set->backend = m_impl->backend;
    set->summary = *summary;
    set->count = points.count;
    set->origin = core::preparedOrigin(*summary, options.origin);
    if (!summary->floatExact || set->origin != glm::dvec3(0.0)) {
        if (auto err = core::checkShiftedRange(points, summary->box, set->origin, "to prepare")) return *err;
        if (auto err = core::checkShiftedExtent(summary->box, set->origin, "to prepare")) return *err;
    }
    set->floats = core::roundedCopy(points, set->origin, m_impl->options.threads);
    set->doubleInput = points.scalar == Scalar::kFloat64;
    if (!summary->floatExact) {
        set->originals.resize(points.count);
        for (size_t i = 0; i < points.count; ++i) set->originals[i] = points.at(i);
    }
    set->ownScale = core::exactScale(core::searchMagnitude(*summary, set->origin));
    const std::string name = "set#" + std::to_string(++m_impl->preparedCount);
    Result<std::shared_ptr<api::BackendSet>> prepared =
        m_impl->backend->prepare(set->floats, set->ownScale, options.bits, name);
    if (!prepared) return prepared.error();
    set->set = std::move(prepared.value());
    return PreparedSet(std::move(set));
}

namespace {

using SetPair = std::pair<const PreparedSet::Impl*, const PreparedSet::Impl*>;

// Route::kSmallPairScan of prepared sets: the pairs in one submission; each
// reports an equal share of the call's wall time.
std::vector<Result<HausdorffResult>> scanSmallPairs(Engine::Impl& impl, std::span<const SetPair> pairs,
                                                    const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<api::BackendSetPair> sets;
    for (const auto& [a, b] : pairs) sets.emplace_back(a->set.get(), b->set.get());
    std::vector<Result<HausdorffResult>> out = impl.backend->scanPrepared(sets, call);
    const double share = msSince(t0) / double(pairs.size());
    for (size_t i = 0; i < out.size(); ++i) {
        if (!out[i]) continue;
        if (auto err =
                leaveFrame(impl, *out[i], preparedFrame(*pairs[i].first, *pairs[i].second), call, t0)) {
            out[i] = *err;
            continue;
        }
        out[i]->timings.total = share;
    }
    return out;
}

}  // namespace

Result<HausdorffResult> Engine::compute(const PreparedSet& a, const PreparedSet& b, const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    if (auto err = validateCallOptions(call)) return *err;
    const PreparedSet::Impl& ia = *a.m_impl;
    const PreparedSet::Impl& ib = *b.m_impl;
    const api::Plan plan = api::planRoute(preparedShape(*m_impl, ia, ib), call,
                                          m_impl->backend->memoryBudget(), m_impl->backend->caps());
    switch (plan.route) {
        case api::Route::kSmallPairScan: {
            const SetPair pair{&ia, &ib};
            return std::move(scanSmallPairs(*m_impl, std::span(&pair, 1), call)[0]);
        }
        case api::Route::kReframe:
            // Different frames or scales: both indexed afresh in the union's frame.
            return computeViews(*m_impl, ia.input(), ib.input(),
                                CheckedInputs{ia.summary, ib.summary, ia.doubleInput || ib.doubleInput}, call,
                                t0);
        case api::Route::kPrepared:
            return finished(*m_impl, m_impl->backend->computePrepared(*ia.set, *ib.set, call),
                            preparedFrame(ia, ib), call, t0);
        default: return refusal(plan);
    }
}

std::vector<Result<HausdorffResult>> Engine::computeBatch(std::span<const PreparedSet> sets,
                                                          std::span<const PairRef> pairs,
                                                          const CallOptions& given) {
    std::vector<std::optional<Result<HausdorffResult>>> out(pairs.size());
    CallOptions call = given;
    call.perPointReady = nullptr;  // compute() calls only (CallOptions::perPointReady)
    const bool cancelled = call.cancel != nullptr && call.cancel->load();
    const bool callValid = !validateCallOptions(call).has_value();
    const api::MemoryBudget budget = m_impl->backend->memoryBudget();
    const api::BackendCaps caps = m_impl->backend->caps();
    std::vector<size_t> scanned;
    std::vector<SetPair> scannedSets;
    for (size_t i = 0; i < pairs.size(); ++i) {
        const PairRef& p = pairs[i];
        if (p.a >= sets.size() || p.b >= sets.size()) {
            out[i] = Error{ErrorCode::kInvalidArgument, "pair (" + std::to_string(p.a) + ", " +
                                                            std::to_string(p.b) + ") names a set past the " +
                                                            std::to_string(sets.size()) + " given"};
            continue;
        }
        const SetPair setPair{sets[p.a].m_impl.get(), sets[p.b].m_impl.get()};
        if (cancelled || !callValid ||
            api::planRoute(preparedShape(*m_impl, *setPair.first, *setPair.second), call, budget, caps)
                    .route != api::Route::kSmallPairScan)
            continue;
        scanned.push_back(i);
        scannedSets.push_back(setPair);
    }
    if (!scannedSets.empty()) {
        std::vector<Result<HausdorffResult>> results = scanSmallPairs(*m_impl, scannedSets, call);
        for (size_t k = 0; k < scanned.size(); ++k) out[scanned[k]] = std::move(results[k]);
    }
    // The other pairs one after another, the cancel flag checked before each.
    std::vector<Result<HausdorffResult>> done;
    done.reserve(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
        if (!out[i]) {
            const bool stop = call.cancel != nullptr && call.cancel->load();
            out[i] = stop ? Result<HausdorffResult>(
                                Error{ErrorCode::kCancelled, "the call was cancelled (CallOptions::cancel)"})
                          : compute(sets[pairs[i].a], sets[pairs[i].b], call);
        }
        done.push_back(std::move(*out[i]));
    }
    return done;
}

Backend oneShotBackendFor(uint64_t points, const EngineOptions& options) {
    // A device named, or the Vulkan validation layer asked for: the Vulkan path.
    const bool vulkanAsked = options.deviceIndex >= 0 || !options.devices.empty() || options.validation;
    return api::oneShotBackend(options.backend, vulkanAsked, points, core::resolveThreads(options.threads));
}

Result<HausdorffResult> hausdorff(PointView a, PointView b, const Options& options) {
    if (auto err = validatePerPointSizes(a, b, options)) return *err;
    // The engine (a device and its pipelines: 0.2-0.75 s on a discrete GPU)
    // is created while the host checks the points (one read of them); bad
    // input is still reported first, even where no device could be created.
    EngineOptions engineOptions = options;
    engineOptions.backend = oneShotBackendFor(a.count + b.count, options);
    std::future<Result<Engine>> engine =
        std::async(std::launch::async, [&engineOptions] { return Engine::create(engineOptions); });
    Result<CheckedInputs> checked = checkInputs(a, b, options.threads);
    if (!checked) return checked.error();
    if (auto err = validateCallOptions(options)) return *err;
    Result<Engine> created = engine.get();
    if (!created) return created.error();
    return computeViews(*created->m_impl, a, b, *checked, options, std::chrono::steady_clock::now());
}

Result<HausdorffResult> Engine::compute(const DevicePointView& a, const DevicePointView& b) {
    return compute(a, b, m_impl->callDefaults);
}

Result<HausdorffResult> Engine::compute(const DevicePointView& a, const DevicePointView& b,
                                        const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    api::PairShape shape;
    shape.input = api::PairShape::Input::kDeviceViews;
    shape.a = a.count;
    shape.b = b.count;
    const api::Plan plan =
        api::planRoute(shape, call, m_impl->backend->memoryBudget(), m_impl->backend->caps());
    // A backend that reads no device views, before the call's own checks; the budget after them.
    if (plan.route == api::Route::kRefused && plan.code != ErrorCode::kOutOfMemory) return refusal(plan);
    if (auto err = validateCallOptions(call)) return *err;
    if (auto err = api::checkDeviceView(a, "A")) return *err;
    if (auto err = api::checkDeviceView(b, "B")) return *err;
    if (plan.route == api::Route::kRefused) return refusal(plan);
    // The host cannot read device views: the device's own proof stands, or the call fails.
    Frame frame;
    frame.onHost = false;
    Result<HausdorffResult> r = m_impl->backend->computeDeviceViews(a, b, call);
    if (!r) return r;
    frame.origin = r->origin;  // the frame the device chose
    if (auto err = leaveFrame(*m_impl, *r, frame, call, t0)) return *err;
    return r;
}

Result<PreparedSet> Engine::prepare(const DevicePointView& points, const PrepareOptions& options) {
    if (const std::string& no = m_impl->backend->caps().noDeviceViews; !no.empty())
        return Error{ErrorCode::kInvalidArgument, no};
    if (auto err = validateBits(options.bits)) return *err;
    if (options.origin)
        if (auto err = core::checkOrigin(*options.origin, "PrepareOptions::origin")) return *err;
    const std::string name = "set#" + std::to_string(++m_impl->preparedCount);
    if (auto err = api::checkDeviceView(points, "to prepare")) return *err;
    Result<api::DeviceViewSet> g =
        m_impl->backend->prepareDeviceView(points, options.origin, options.bits, name);
    if (!g) return g.error();
    auto set = std::make_shared<PreparedSet::Impl>();
    set->backend = m_impl->backend;
    set->summary = g->summary;
    set->origin = g->origin;
    set->count = points.count;
    set->onDevice = true;
    set->ownScale = 1.0;  // prepareDeviceView refuses sets that need the exact scale
    set->set = std::move(g->set);
    return PreparedSet(std::move(set));
}

}  // namespace rthdist
