// Public entry of rthdist: input validation, backend choice, and the Engine
// that keeps a Vulkan device and its pipelines between calls.
#include "rthdist/rthdist.hpp"
#include "rthdist/version.hpp"

#include <chrono>
#include <cmath>
#include <optional>

#include <string>
#include "algo/index_space.hpp"

#include "algo/gpu_hausdorff.hpp"
#include "algo/input_frame.hpp"
#include "cpu/cpu_hausdorff.hpp"
#include "gpu/context.hpp"

namespace rthdist {

const char* versionString() { return RTHDIST_VERSION_STRING; }

const char* backendName(Backend backend) {
    switch (backend) {
        case Backend::kAuto: return "auto";
        case Backend::kRayQuery: return "ray-query";
        case Backend::kRtPipeline: return "rt-pipeline";
        case Backend::kCpu: return "cpu";
    }
    return "?";
}

bool parseBackend(const std::string& text, Backend& out) {
    for (Backend b : {Backend::kAuto, Backend::kRayQuery, Backend::kRtPipeline, Backend::kCpu}) {
        if (text == backendName(b)) {
            out = b;
            return true;
        }
    }
    return false;
}

namespace {

std::optional<Error> validateOptions(const Options& o) {
    if (o.bits < 0 || o.bits > algo::kMaxBits) {
        return Error{ErrorCode::kInvalidArgument,
                     "bits must be 0 (auto) or 1.." + std::to_string(algo::kMaxBits)};
    }
    if (!(o.radiusGrowth > 1.0f) || !std::isfinite(o.radiusGrowth)) {
        return Error{ErrorCode::kInvalidArgument, "radiusGrowth must be a finite number > 1"};
    }
    if (o.threads < 0) return Error{ErrorCode::kInvalidArgument, "threads must be >= 0"};
    return std::nullopt;
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// auto picks a Vulkan backend only on a device with RT hardware paths that is
// not a software rasterizer: on lavapipe (VK_PHYSICAL_DEVICE_TYPE_CPU) the
// native CPU backend is 10-100x faster (docs/bench). An explicit --device
// keeps the Vulkan path on whatever device it names.
bool hardwareRtDevice(const Options& o) {
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

}  // namespace

struct Engine::Impl {
    Options options;
    std::unique_ptr<gpu::Context> context;    // null for the CPU backend
    std::unique_ptr<algo::GpuHausdorff> gpu;  // null for the CPU backend
    Backend backend = Backend::kCpu;
    std::string deviceName = "cpu";
    double setupMs = 0.0;
};

Engine::Engine(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Engine::Engine(Engine&&) noexcept = default;
Engine& Engine::operator=(Engine&&) noexcept = default;
Engine::~Engine() = default;

Result<Engine> Engine::create(const Options& options) {
    if (auto err = validateOptions(options)) return *err;
    auto t0 = std::chrono::steady_clock::now();
    auto impl = std::make_unique<Impl>();
    impl->options = options;
    if (options.backend == Backend::kCpu ||
        (options.backend == Backend::kAuto && !hardwareRtDevice(options))) {
        impl->backend = Backend::kCpu;
        return Engine(std::move(impl));
    }
    auto ctx = gpu::Context::create(options.backend, options.deviceIndex, options.validation);
    if (!ctx) return ctx.error();
    impl->context = std::move(ctx.value());
    auto g = algo::GpuHausdorff::create(*impl->context);
    if (!g) return g.error();
    impl->gpu = std::move(g.value());
    impl->backend = impl->context->backend();
    impl->deviceName = impl->context->deviceName();
    impl->setupMs = msSince(t0);
    return Engine(std::move(impl));
}

const std::string& Engine::deviceName() const { return m_impl->deviceName; }
Backend Engine::backend() const { return m_impl->backend; }

namespace {

// The computation: one pass per set checks the coordinates and takes its box
// (input_frame.hpp); the backends search float32 sets (shifted when an input
// is double); witnesses and distances come back in the original coordinates.
struct CheckedInputs {
    algo::SetSummary a, b;
};

Result<CheckedInputs> checkInputs(const PointView& a, const PointView& b) {
    Result<algo::SetSummary> sa = algo::summarizeSet(a, "A");
    if (!sa) return sa.error();
    Result<algo::SetSummary> sb = algo::summarizeSet(b, "B");
    if (!sb) return sb.error();
    return CheckedInputs{*sa, *sb};
}

Result<HausdorffResult> computeViews(Engine::Impl& impl, const PointView& a, const PointView& b,
                                     const CheckedInputs& checked, std::chrono::steady_clock::time_point t0) {
    const glm::dvec3 origin = algo::searchOrigin(checked.a, checked.b);
    const algo::FloatSet fa(a, origin), fb(b, origin);
    Result<HausdorffResult> r = impl.gpu ? impl.gpu->compute(fa.span(), fb.span(), impl.options)
                                         : cpu::cpuHausdorff(fa.span(), fb.span(), impl.options);
    if (!r) return r;
    const bool copied = fa.span().data() != a.data || fb.span().data() != b.data;
    if (copied) algo::restoreOriginal(*r, a, b);
    r->origin = origin;
    r->timings.setup = impl.setupMs;
    impl.setupMs = 0.0;  // only the first call pays for creation
    r->timings.total = msSince(t0);
    if (impl.context) r->validationMessages = impl.context->validationMessageCount();
    return r;
}

}  // namespace

Result<HausdorffResult> Engine::compute(PointView a, PointView b) {
    const auto t0 = std::chrono::steady_clock::now();
    Result<CheckedInputs> checked = checkInputs(a, b);
    if (!checked) return checked.error();
    return computeViews(*m_impl, a, b, *checked, t0);
}

Result<HausdorffResult> hausdorff(PointView a, PointView b, const Options& options) {
    // Checked before the engine exists: bad input is reported as such even
    // where no device could be created; the points are read once.
    Result<CheckedInputs> checked = checkInputs(a, b);
    if (!checked) return checked.error();
    auto engine = Engine::create(options);
    if (!engine) return engine.error();
    return computeViews(*engine->m_impl, a, b, *checked, std::chrono::steady_clock::now());
}

}  // namespace rthdist
