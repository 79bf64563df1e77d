// Public entry of rthdist: input validation, backend choice, and the Engine
// that keeps a Vulkan device and its pipelines between calls.
#include "rthdist/rthdist.hpp"
#include "rthdist/version.hpp"
#include "rthdist/vulkan_interop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "api/certify.hpp"
#include "api/device_views.hpp"
#include "api/out_of_core.hpp"
#include "core/index_space.hpp"
#include "core/input_frame.hpp"
#include "core/input_limits.hpp"
#include "core/stopwatch.hpp"
#include "core/thread_pool.hpp"
#include "cpu/cpu_hausdorff.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu_algo/gpu_hausdorff.hpp"

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

// auto picks a Vulkan backend only on a device with RT hardware paths that is
// not a software rasterizer: on lavapipe (VK_PHYSICAL_DEVICE_TYPE_CPU) the
// native CPU backend is 10-100x faster (docs/bench). An explicit --device
// keeps the Vulkan path on whatever device it names.
bool hardwareRtDevice(const EngineOptions& o) {
    auto devices = listDevices();
    if (!devices) return false;
    for (const DeviceInfo& d : devices.value()) {
        if (!(d.rayQuery || d.rtPipeline)) continue;
        if (o.deviceIndex >= 0) {
            if (d.index == o.deviceIndex) return true;
            continue;
        }
        if (d.type != "cpu") return true;
    }
    return false;
}

// The device of an Engine, shared with the sets it prepared (their buffers
// must be destroyed before it). Empty on the CPU backend.
struct Device {
    std::unique_ptr<gpu::Context> context;
    std::unique_ptr<gpu_algo::GpuHausdorff> gpu;  // destroyed before the context
};

}  // namespace

struct Engine::Impl {
    EngineOptions options;
    CallOptions callDefaults;        // compute(a, b) without call options
    std::shared_ptr<Device> device;  // never null; identifies the Engine's prepared sets
    // EngineOptions::devices past the first: the other lanes of one-shot calls.
    std::vector<std::unique_ptr<Device>> moreDevices;
    Backend backend = Backend::kCpu;
    std::string deviceName = "cpu";
    double setupMs = 0.0;
    uint64_t preparedCount = 0;
};

struct PreparedSet::Impl {
    std::shared_ptr<Device> device;  // keeps the device alive; first member, destroyed last
    core::SetSummary summary;
    glm::dvec3 origin{0.0};
    std::vector<glm::vec3> floats;      // p - origin rounded: what the backend searches
    std::vector<glm::dvec3> originals;  // the input when it is not float-exact
    double ownScale = 1.0;              // core::exactScale of `floats` alone
    std::shared_ptr<gpu_algo::DeviceSet> gpuSet;
    std::shared_ptr<cpu::CpuSet> cpuSet;
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
int PreparedSet::bits() const {
    return m_impl->gpuSet ? gpu_algo::GpuHausdorff::bits(*m_impl->gpuSet) : m_impl->cpuSet->order.grid.bits;
}
uint64_t PreparedSet::deviceBytes() const {
    return m_impl->gpuSet ? gpu_algo::GpuHausdorff::deviceBytes(*m_impl->gpuSet) : 0;
}
uint64_t PreparedSet::hostBytes() const {
    uint64_t bytes =
        m_impl->floats.capacity() * sizeof(glm::vec3) + m_impl->originals.capacity() * sizeof(glm::dvec3);
    if (m_impl->cpuSet) bytes += m_impl->cpuSet->hostBytes();
    return bytes;
}

Engine::Engine(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Engine::Engine(Engine&&) noexcept = default;
Engine& Engine::operator=(Engine&&) noexcept = default;
Engine::~Engine() = default;

namespace {

// One device of an Engine: its context and the GPU algorithm on it.
// `borrowed`: the embedder's device (vulkan_interop.hpp) instead of one of ours.
std::optional<Error> openDevice(const EngineOptions& options, Backend backend, int deviceIndex,
                                Device& device, const VulkanDevice* borrowed = nullptr) {
    const Tuning& tuning = *options.tuning;  // Engine::create fills it
    auto ctx = borrowed ? gpu::Context::borrow(*borrowed, backend, options.validation, tuning)
                        : gpu::Context::create(backend, deviceIndex, options.validation, tuning);
    if (!ctx) return ctx.error();
    device.context = std::move(ctx.value());
    const std::string cacheDir = options.pipelineCacheDir == "off"  ? std::string()
                                 : options.pipelineCacheDir.empty() ? tuning.pipelineCacheDir
                                                                    : options.pipelineCacheDir;
    auto g = gpu_algo::GpuHausdorff::create(*device.context, cacheDir, options.threads, tuning);
    if (!g) return g.error();
    device.gpu = std::move(g.value());
    return std::nullopt;
}

// The engine's tuning: the caller's, else the environment's (the one read of
// it, rthdist/tuning.hpp); the worker pool's polling is process-wide.
void settleTuning(EngineOptions& options) {
    if (!options.tuning) options.tuning = tuningFromEnvironment();
    if (options.tuning->poolSpinMicros)
        core::setPoolSpin(std::chrono::microseconds(*options.tuning->poolSpinMicros));
}

}  // namespace

Result<Engine> Engine::create(const EngineOptions& given) {
    if (auto err = validateEngineOptions(given)) return *err;
    auto t0 = std::chrono::steady_clock::now();
    auto impl = std::make_unique<Impl>();
    impl->options = given;
    settleTuning(impl->options);
    const EngineOptions& options = impl->options;
    if (!options.devices.empty()) impl->options.deviceIndex = options.devices.front();
    impl->device = std::make_shared<Device>();
    if (options.backend == Backend::kCpu ||
        (options.backend == Backend::kAuto && !hardwareRtDevice(options))) {
        if (options.devices.size() > 1) {
            return Error{
                ErrorCode::kInvalidArgument,
                "several devices (EngineOptions::devices) need a GPU backend; the " +
                    std::string(options.backend == Backend::kCpu ? "cpu backend was asked for"
                                                                 : "first device has no RT hardware")};
        }
        impl->backend = Backend::kCpu;
        return Engine(std::move(impl));
    }
    if (auto err = openDevice(options, options.backend, options.deviceIndex, *impl->device)) return *err;
    impl->backend = impl->device->context->backend();
    impl->deviceName = impl->device->context->deviceName();
    for (size_t i = 1; i < options.devices.size(); ++i) {
        auto device = std::make_unique<Device>();
        if (auto err = openDevice(options, impl->backend, options.devices[i], *device)) {
            return Error{err->code, "device " + std::to_string(options.devices[i]) +
                                        " of EngineOptions::devices: " + err->message};
        }
        impl->deviceName += " + " + device->context->deviceName();
        impl->moreDevices.push_back(std::move(device));
    }
    impl->setupMs = msSince(t0);
    return Engine(std::move(impl));
}

Result<Engine> Engine::create(const Options& options) {
    if (auto err = validateCallOptions(options)) return *err;
    Result<Engine> engine = create(static_cast<const EngineOptions&>(options));
    if (engine) engine->m_impl->callDefaults = static_cast<const CallOptions&>(options);
    return engine;
}

Result<Engine> Engine::create(const VulkanDevice& device, const EngineOptions& given) {
    if (auto err = validateEngineOptions(given)) return *err;
    if (given.backend == Backend::kCpu)
        return Error{ErrorCode::kInvalidArgument, "the cpu backend takes no Vulkan device (VulkanDevice)"};
    auto t0 = std::chrono::steady_clock::now();
    auto impl = std::make_unique<Impl>();
    impl->options = given;
    settleTuning(impl->options);
    impl->options.devices.clear();
    impl->device = std::make_shared<Device>();
    if (auto err = openDevice(impl->options, given.backend, -1, *impl->device, &device)) return *err;
    impl->backend = impl->device->context->backend();
    impl->deviceName = impl->device->context->deviceName();
    impl->setupMs = msSince(t0);
    return Engine(std::move(impl));
}

const std::string& Engine::deviceName() const { return m_impl->deviceName; }
Backend Engine::backend() const { return m_impl->backend; }
std::string Engine::pipelineCachePath() const {
    return m_impl->device->gpu ? m_impl->device->gpu->pipelineCachePath() : std::string();
}
std::string Engine::pipelineCacheStatus() const {
    return m_impl->device->gpu ? m_impl->device->gpu->pipelineCacheStatus() : std::string("none");
}

namespace {

// The computation: one pass per set checks the coordinates and takes its box
// (input_frame.hpp); the backends search float32 sets (shifted when an input
// is double); witnesses and distances come back in the original coordinates.
struct CheckedInputs {
    core::SetSummary a, b;
};

Result<CheckedInputs> checkInputs(const PointView& a, const PointView& b, int threads) {
    Result<core::SetSummary> sa = core::summarizeSet(a, "A", threads);
    if (!sa) return sa.error();
    Result<core::SetSummary> sb = core::summarizeSet(b, "B", threads);
    if (!sb) return sb.error();
    return CheckedInputs{*sa, *sb};
}

// The Engine's devices in lane order (out_of_core.hpp): the first device, then
// EngineOptions::devices past it.
size_t laneCount(const Engine::Impl& impl) { return 1 + impl.moreDevices.size(); }
Device& laneDevice(const Engine::Impl& impl, size_t lane) {
    return lane == 0 ? *impl.device : *impl.moreDevices[lane - 1];
}

// CallOptions::perPointReady for each direction of a complete result that
// the backend did not hand back early itself (GpuHausdorff::handedBack).
void handBackTheRest(const Engine::Impl& impl, const HausdorffResult& r, const CallOptions& call) {
    if (!call.perPointReady) return;
    const uint32_t done = impl.device->gpu ? impl.device->gpu->handedBack() : 0u;
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
    r.validationMessages = 0;
    for (size_t lane = 0; lane < laneCount(impl); ++lane) {
        if (laneDevice(impl, lane).context)
            r.validationMessages += laneDevice(impl, lane).context->validationMessageCount();
    }
}

// What one backend call may hold (out_of_core.hpp): the caller's
// EngineOptions::memoryBudget, else on a GPU three quarters of the device's
// budget; set pieces up to the largest allocation the device promises.
api::MemoryBudget memoryBudget(const Engine::Impl& impl) {
    api::MemoryBudget budget;
    if (impl.options.memoryBudget > 0) {
        budget.bytes = impl.options.memoryBudget;
        budget.source = "EngineOptions::memoryBudget";
    }
    if (!impl.device->context) return budget;
    if (impl.options.memoryBudget == 0) {
        budget.bytes = UINT64_MAX;
        budget.source = "3/4 of the device's memory budget";
    }
    for (size_t lane = 0; lane < laneCount(impl); ++lane) {  // the smallest device sets the pieces
        const gpu::DeviceLimits& limits = laneDevice(impl, lane).context->limits();
        if (impl.options.memoryBudget == 0)
            budget.bytes = std::min(budget.bytes, limits.deviceBudgetBytes / 4 * 3);
        budget.maxPiecePoints =
            std::min({budget.maxPiecePoints, limits.maxAllocationBytes / api::kLargestBufferBytesPerPoint,
                      limits.maxBufferBytes / api::kLargestBufferBytesPerPoint, limits.maxPrimitives});
    }
    return budget;
}

// One call of the Engine's backend, on device `lane`, on float sets of one
// frame and scale.
Result<HausdorffResult> runBackend(Engine::Impl& impl, size_t lane, std::span<const glm::vec3> a,
                                   std::span<const glm::vec3> b, double scale, const CallOptions& call) {
    if (impl.device->gpu) return laneDevice(impl, lane).gpu->compute(a, b, scale, call);
    Options options;
    static_cast<CallOptions&>(options) = call;
    static_cast<EngineOptions&>(options) = impl.options;
    return cpu::cpuHausdorff(a, b, options);
}

// The pair in one backend call (on the first device) when it fits the
// memory budget, else (or when the device runs out of memory under the
// automatic budget) in pieces spread over the Engine's devices. A pair that
// fits stays on one device: split over several, every device would index
// all the targets and the host stages each set once per device (H200s,
// 300M x 300M points: 5.8 s on one, 20.7 s on two; README "Several GPUs").
// With several devices, a pair whose every device's share (its queries and
// all targets) fits the bytes runs with the targets whole, past the pieces'
// maxMemoryAllocationSize bound, as one device tries the whole pair (a
// device short of memory then halves the budget: out_of_core.hpp).
Result<HausdorffResult> runWithinBudget(Engine::Impl& impl, std::span<const glm::vec3> a,
                                        std::span<const glm::vec3> b, double scale, const CallOptions& call) {
    const api::MemoryBudget budget = memoryBudget(impl);
    const uint64_t lanes = laneCount(impl);
    const bool automatic = impl.options.memoryBudget == 0 && impl.device->gpu;
    if (api::fitsOneCall(budget, a.size(), b.size())) {
        Result<HausdorffResult> r = runBackend(impl, 0, a, b, scale, call);
        if (r || r.error().code != ErrorCode::kOutOfMemory || !automatic) return r;
        // A direction already handed back (perPointReady) is not handed back again from pieces.
        if (impl.device->gpu && impl.device->gpu->handedBack() != 0) return r;
    }
    const std::function<void()> release = [&impl] {
        for (size_t lane = 0; lane < laneCount(impl); ++lane)
            if (laneDevice(impl, lane).gpu) laneDevice(impl, lane).gpu->releaseScratch();
    };
    const api::DirectedCall directed = [&](int lane, std::span<const glm::vec3> q,
                                           std::span<const glm::vec3> t, const CallOptions& piece) {
        return runBackend(impl, size_t(lane), q, t, scale, piece);
    };
    const api::RecycleCall recycle = [&impl](int lane, PerPoint&& spent) {
        if (laneDevice(impl, size_t(lane)).gpu)
            laneDevice(impl, size_t(lane)).gpu->recyclePerPoint(std::move(spent));
    };
    const bool sharesFit = api::fitsOneCall(budget, (a.size() + lanes - 1) / lanes, b.size()) &&
                           api::fitsOneCall(budget, (b.size() + lanes - 1) / lanes, a.size());
    api::MemoryBudget pieces = budget;
    if (lanes > 1 && sharesFit) pieces.maxPiecePoints = UINT64_MAX;  // a kOutOfMemory halves the bytes
    release();
    Result<HausdorffResult> r = api::computeInPieces(a, b, scale, call, pieces, directed, release, int(lanes),
                                                     impl.options.threads, recycle);
    release();  // the pieces' scratch is no use to the next call
    if (!r) return r;
    r->backend = impl.backend;
    r->device = impl.deviceName;
    return r;
}

Result<HausdorffResult> computeViews(Engine::Impl& impl, const PointView& a, const PointView& b,
                                     const CheckedInputs& checked, const CallOptions& call,
                                     std::chrono::steady_clock::time_point t0) {
    if (auto err = validateCallOptions(call)) return *err;
    const glm::dvec3 origin = core::searchOrigin(checked.a, checked.b);
    if (auto err = core::checkPairFrame(a, checked.a.box, checked.a.floatExact, b, checked.b.box,
                                        checked.b.floatExact, origin))
        return *err;
    const core::FloatSet fa(a, origin, impl.options.threads), fb(b, origin, impl.options.threads);
    const double scale = core::exactScale(
        std::max(core::searchMagnitude(checked.a, origin), core::searchMagnitude(checked.b, origin)));
    Result<HausdorffResult> r = runWithinBudget(impl, fa.span(), fb.span(), scale, call);
    if (!r) return r;
    const bool copied = fa.span().data() != a.data || fb.span().data() != b.data;
    if (copied) core::restoreOriginal(*r, a, b, impl.options.threads);
    r->origin = origin;
    if (auto err = api::settleCertificates(*r, a, b, impl.options.threads)) return *err;
    finishResult(impl, *r, call, t0);
    return r;
}

// Whether two prepared sets can be searched as they are: one frame, within
// the contract's bound, and one exact scale.
bool shareFrame(const PreparedSet::Impl& a, const PreparedSet::Impl& b) {
    if (a.origin != b.origin || !core::frameKeepsBound(a.summary, b.summary, a.origin)) return false;
    const double pairScale = std::min(a.ownScale, b.ownScale);  // of the larger magnitude
    return a.ownScale == pairScale && b.ownScale == pairScale;
}

}  // namespace

Result<HausdorffResult> Engine::compute(PointView a, PointView b) {
    return compute(a, b, m_impl->callDefaults);
}

namespace {

// A one-shot GPU call on packed float arrays: the device checks, bounds and
// samples the points (GpuHausdorff::computePacked); the host only copies them.
Result<HausdorffResult> computeIngested(Engine::Impl& impl, const PointView& a, const PointView& b,
                                        const CallOptions& call, std::chrono::steady_clock::time_point t0) {
    if (auto err = core::checkShape(a, "A")) return *err;
    if (auto err = core::checkShape(b, "B")) return *err;
    if (auto err = validateCallOptions(call)) return *err;
    auto asVec3 = [](const PointView& v) {
        return std::span<const glm::vec3>(static_cast<const glm::vec3*>(v.data), v.count);
    };
    Result<HausdorffResult> r = impl.device->gpu->computePacked(asVec3(a), asVec3(b), call);
    if (!r) return r;
    r->origin = glm::dvec3(0.0);
    if (auto err = api::settleCertificates(*r, a, b, impl.options.threads)) return *err;
    finishResult(impl, *r, call, t0);
    return r;
}

}  // namespace

Result<HausdorffResult> Engine::compute(PointView a, PointView b, const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    // Small pairs are scanned whole from the host's float copies
    // (GpuHausdorff::scansWhole): the points are checked on the host.
    if (m_impl->device->gpu && a.packedFloat() && b.packedFloat() &&
        !m_impl->device->gpu->scansWhole(a.count, b.count, call) &&
        gpu_algo::GpuHausdorff::ingests(a.count, b.count) &&
        api::fitsOneCall(memoryBudget(*m_impl), a.count, b.count))
        return computeIngested(*m_impl, a, b, call, t0);
    if (auto err = validatePerPointSizes(a, b, call)) return *err;
    Result<CheckedInputs> checked = checkInputs(a, b, m_impl->options.threads);
    if (!checked) return checked.error();
    return computeViews(*m_impl, a, b, *checked, call, t0);
}

void Engine::recycle(HausdorffResult&& spent) {
    if (m_impl->device->gpu)
        m_impl->device->gpu->recyclePerPoint(std::move(spent.aNearest), std::move(spent.bNearest));
}

Result<PreparedSet> Engine::prepare(PointView points, const PrepareOptions& options) {
    if (auto err = validateBits(options.bits)) return *err;
    if (auto err = validatePreparedSize(points)) return *err;
    if (options.origin)
        if (auto err = core::checkOrigin(*options.origin, "PrepareOptions::origin")) return *err;
    Result<core::SetSummary> summary = core::summarizeSet(points, "to prepare", m_impl->options.threads);
    if (!summary) return summary.error();
    auto set = std::make_shared<PreparedSet::Impl>();
    set->device = m_impl->device;
    set->summary = *summary;
    set->count = points.count;
    set->origin = core::preparedOrigin(*summary, options.origin);
    if (!summary->floatExact || set->origin != glm::dvec3(0.0)) {
        if (auto err = core::checkShiftedRange(points, summary->box, set->origin, "to prepare")) return *err;
        if (auto err = core::checkShiftedExtent(summary->box, set->origin, "to prepare")) return *err;
    }
    set->floats = core::roundedCopy(points, set->origin, m_impl->options.threads);
    if (!summary->floatExact) {
        set->originals.resize(points.count);
        for (size_t i = 0; i < points.count; ++i) set->originals[i] = points.at(i);
    }
    set->ownScale = core::exactScale(core::searchMagnitude(*summary, set->origin));
    if (m_impl->device->gpu) {
        Timings timings;
        const std::string name = "set#" + std::to_string(++m_impl->preparedCount);
        auto g = m_impl->device->gpu->prepare(set->floats, set->ownScale, options.bits, name, timings);
        if (!g) return g.error();
        set->gpuSet = std::move(g.value());
    } else {
        set->cpuSet = cpu::prepareCpuSet(set->floats, set->ownScale, options.bits, m_impl->options.threads);
    }
    return PreparedSet(std::move(set));
}

namespace {

using SetPair = std::pair<const PreparedSet::Impl*, const PreparedSet::Impl*>;

// A pair of computeBatch that the GPU scans whole with the batch's other
// small pairs (gpu_algo/small_pairs.hpp): sets of this Engine's GPU, host
// arrays, one origin that keeps the bound (their scales may differ).
bool scannedWhole(const Engine::Impl& impl, const SetPair& p) {
    const PreparedSet::Impl& a = *p.first;
    const PreparedSet::Impl& b = *p.second;
    return impl.device->gpu && a.device == impl.device && b.device == impl.device && !a.onDevice &&
           !b.onDevice && a.origin == b.origin && core::frameKeepsBound(a.summary, b.summary, a.origin) &&
           impl.device->gpu->scansWhole(*a.gpuSet, *b.gpuSet);
}

// The small pairs in one submission; each reports an equal share of the
// call's wall time.
std::vector<Result<HausdorffResult>> scanSmallPairs(Engine::Impl& impl, std::span<const SetPair> pairs,
                                                    const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::pair<const gpu_algo::DeviceSet*, const gpu_algo::DeviceSet*>> sets;
    for (const auto& [a, b] : pairs) sets.emplace_back(a->gpuSet.get(), b->gpuSet.get());
    std::vector<Result<HausdorffResult>> out = impl.device->gpu->computeSmallPairs(sets, call);
    const double share = msSince(t0) / double(pairs.size());
    for (size_t i = 0; i < out.size(); ++i) {
        if (!out[i]) continue;
        const PreparedSet::Impl& a = *pairs[i].first;
        const PreparedSet::Impl& b = *pairs[i].second;
        if (!a.originals.empty() || !b.originals.empty())
            core::restoreOriginal(*out[i], a.input(), b.input(), impl.options.threads);
        out[i]->origin = a.origin;
        if (auto err = api::settleCertificates(*out[i], a.input(), b.input(), impl.options.threads)) {
            out[i] = *err;
            continue;
        }
        finishResult(impl, *out[i], call, t0);
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
    if (ia.device != m_impl->device || ib.device != m_impl->device)
        return Error{ErrorCode::kInvalidArgument, "a prepared set belongs to another Engine"};
    if ((ia.onDevice || ib.onDevice) &&
        (!shareFrame(ia, ib) || !ia.originals.empty() || !ib.originals.empty())) {
        return Error{ErrorCode::kInvalidArgument,
                     "a set prepared from a device view keeps no host copy: it meets only sets of its frame "
                     "(prepare both with one PrepareOptions::origin) whose coordinates are float values or "
                     "also device views"};
    }
    if (const SetPair pair{&ia, &ib}; scannedWhole(*m_impl, pair))
        return std::move(scanSmallPairs(*m_impl, std::span(&pair, 1), call)[0]);
    if (!shareFrame(ia, ib)) {
        // Different frames or scales: both indexed afresh in the union's frame.
        return computeViews(*m_impl, ia.input(), ib.input(), CheckedInputs{ia.summary, ib.summary}, call, t0);
    }
    Result<HausdorffResult> r =
        m_impl->device->gpu ? m_impl->device->gpu->compute(*ia.gpuSet, *ib.gpuSet, call)
                            : cpu::cpuHausdorff(*ia.cpuSet, *ib.cpuSet, call, m_impl->options.threads);
    if (!r) return r;
    if (!ia.originals.empty() || !ib.originals.empty())
        core::restoreOriginal(*r, ia.input(), ib.input(), m_impl->options.threads);
    r->origin = ia.origin;
    // Sets prepared from device views keep no host copy: their proof is the device's own.
    const bool onHost = !ia.onDevice && !ib.onDevice;
    if (auto err =
            api::settleCertificates(*r, onHost ? ia.input() : PointView{}, onHost ? ib.input() : PointView{},
                                    m_impl->options.threads, onHost))
        return *err;
    finishResult(*m_impl, *r, call, t0);
    return r;
}

std::vector<Result<HausdorffResult>> Engine::computeBatch(std::span<const PreparedSet> sets,
                                                          std::span<const PairRef> pairs,
                                                          const CallOptions& given) {
    std::vector<std::optional<Result<HausdorffResult>>> out(pairs.size());
    CallOptions call = given;
    call.perPointReady = nullptr;  // compute() calls only (CallOptions::perPointReady)
    const bool cancelled = call.cancel != nullptr && call.cancel->load();
    const bool callValid = !validateCallOptions(call).has_value();
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
        if (cancelled || !callValid || !scannedWhole(*m_impl, setPair)) continue;
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

Result<HausdorffResult> hausdorff(PointView a, PointView b, const Options& options) {
    // Checked before the engine exists: bad input is reported as such even
    // where no device could be created; the points are read once.
    if (auto err = validatePerPointSizes(a, b, options)) return *err;
    Result<CheckedInputs> checked = checkInputs(a, b, options.threads);
    if (!checked) return checked.error();
    if (auto err = validateCallOptions(options)) return *err;
    auto engine = Engine::create(static_cast<const EngineOptions&>(options));
    if (!engine) return engine.error();
    return computeViews(*engine->m_impl, a, b, *checked, options, std::chrono::steady_clock::now());
}

}  // namespace rthdist

namespace rthdist {

namespace {

// The Engine's device when it can read device views, or why not.
std::optional<Error> deviceInputEngine(const Engine::Impl& impl) {
    if (!impl.device->gpu)
        return Error{
            ErrorCode::kInvalidArgument,
            "device views (DevicePointView) need a GPU backend: the cpu backend cannot read VkBuffers"};
    if (!impl.device->context->borrowed())
        return Error{ErrorCode::kInvalidArgument,
                     "device views (DevicePointView) need an Engine created on your VkDevice "
                     "(Engine::create(const VulkanDevice&, ...))"};
    return std::nullopt;
}

}  // namespace

Result<HausdorffResult> Engine::compute(const DevicePointView& a, const DevicePointView& b) {
    return compute(a, b, m_impl->callDefaults);
}

Result<HausdorffResult> Engine::compute(const DevicePointView& a, const DevicePointView& b,
                                        const CallOptions& call) {
    const auto t0 = std::chrono::steady_clock::now();
    if (auto err = deviceInputEngine(*m_impl)) return *err;
    if (auto err = validateCallOptions(call)) return *err;
    const VkDevice device = m_impl->device->context->device();
    Result<gpu_algo::DeviceInput> da = api::checkDeviceView(a, "A", device);
    if (!da) return da.error();
    Result<gpu_algo::DeviceInput> db = api::checkDeviceView(b, "B", device);
    if (!db) return db.error();
    if (!api::fitsOneCall(memoryBudget(*m_impl), a.count, b.count))
        return Error{ErrorCode::kOutOfMemory, "device views of " + std::to_string(a.count) + " and " +
                                                  std::to_string(b.count) +
                                                  " points do not fit the memory budget of one call "
                                                  "(device input is not split into pieces)"};
    Result<HausdorffResult> r = m_impl->device->gpu->computeDevice(*da, *db, call);
    if (!r) return r;
    // The host cannot read device views: the device's own proof stands, or the call fails.
    if (auto err = api::settleCertificates(*r, PointView{}, PointView{}, m_impl->options.threads, false))
        return *err;
    finishResult(*m_impl, *r, call, t0);
    return r;
}

Result<PreparedSet> Engine::prepare(const DevicePointView& points, const PrepareOptions& options) {
    if (auto err = deviceInputEngine(*m_impl)) return *err;
    if (auto err = validateBits(options.bits)) return *err;
    if (options.origin)
        if (auto err = core::checkOrigin(*options.origin, "PrepareOptions::origin")) return *err;
    Result<gpu_algo::DeviceInput> view =
        api::checkDeviceView(points, "to prepare", m_impl->device->context->device());
    if (!view) return view.error();
    Timings timings;
    const std::string name = "set#" + std::to_string(++m_impl->preparedCount);
    auto g = m_impl->device->gpu->prepareDevice(*view, options.origin, options.bits, name, timings);
    if (!g) return g.error();
    auto set = std::make_shared<PreparedSet::Impl>();
    set->device = m_impl->device;
    set->summary = g->summary;
    set->origin = g->origin;
    set->count = points.count;
    set->onDevice = true;
    set->ownScale = 1.0;  // prepareDevice refuses sets that need the exact scale
    set->gpuSet = std::move(g->set);
    return PreparedSet(std::move(set));
}

}  // namespace rthdist
