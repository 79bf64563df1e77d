// The GPU algorithm (gpu_algo::GpuHausdorff) as the Engine's backend
// (api/backend.hpp), on one device or several (EngineOptions::devices: the
// lanes of one-shot calls' pieces).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "api/backend.hpp"
#include "api/device_views.hpp"
#include "core/stopwatch.hpp"
#include "gpu/context.hpp"
#include "gpu_algo/gpu_hausdorff.hpp"

namespace rthdist::api {

namespace {

// One device: its context and the GPU algorithm on it.
struct Device {
    std::unique_ptr<gpu::Context> context;
    std::unique_ptr<gpu_algo::GpuHausdorff> gpu;  // destroyed before the context
};

// `borrowed`: the embedder's device (vulkan_interop.hpp) instead of one of ours.
std::optional<Error> openDevice(const EngineOptions& options, Backend backend, int deviceIndex,
                                Device& device, const VulkanDevice* borrowed) {
    const Tuning& tuning = *options.tuning;
    const auto t0 = core::Clock::now();
    auto ctx = borrowed ? gpu::Context::borrow(*borrowed, backend, options.validation, tuning)
                        : gpu::Context::create(backend, deviceIndex, options.validation, tuning);
    if (!ctx) return ctx.error();
    device.context = std::move(ctx.value());
    const double contextMs = core::msSince(t0);
    const auto t1 = core::Clock::now();
    const std::string cacheDir = options.pipelineCacheDir == "off"  ? std::string()
                                 : options.pipelineCacheDir.empty() ? tuning.pipelineCacheDir
                                                                    : options.pipelineCacheDir;
    auto g = gpu_algo::GpuHausdorff::create(*device.context, cacheDir, options.threads, tuning);
    if (!g) return g.error();
    device.gpu = std::move(g.value());
    if (device.context->tracingSubmits())
        std::fprintf(stderr, "rthdist setup: device %d opened in %.1f ms (context %.1f, algorithm %.1f)\n",
                     deviceIndex, core::msSince(t0), contextMs, core::msSince(t1));
    return std::nullopt;
}

class GpuSet final : public BackendSet {
public:
    explicit GpuSet(std::shared_ptr<gpu_algo::DeviceSet> set) : set(std::move(set)) {}
    [[nodiscard]] int bits() const override { return gpu_algo::GpuHausdorff::bits(*set); }
    [[nodiscard]] uint64_t deviceBytes() const override { return gpu_algo::GpuHausdorff::deviceBytes(*set); }
    [[nodiscard]] uint64_t hostBytes() const override { return 0; }
    std::shared_ptr<gpu_algo::DeviceSet> set;
};

gpu_algo::DeviceSet& deviceSet(const BackendSet& set) { return *static_cast<const GpuSet&>(set).set; }

class GpuBackend final : public ComputeBackend {
public:
    explicit GpuBackend(const EngineOptions& options) : m_options(options) {}
    GpuBackend(const GpuBackend&) = delete;
    GpuBackend& operator=(const GpuBackend&) = delete;
    // Every lane's buffers, then its device; with RTHDIST_SUBMIT_TRACE, how
    // long each took (freeing tens of GB of device memory is not free).
    ~GpuBackend() override {
        const bool trace =
            !m_lanes.empty() && m_lanes.front()->context && m_lanes.front()->context->tracingSubmits();
        const auto t0 = std::chrono::steady_clock::now();
        for (auto& lane : m_lanes) lane->gpu.reset();
        const auto t1 = std::chrono::steady_clock::now();
        m_lanes.clear();
        if (trace)
            std::fprintf(stderr, "rthdist teardown: buffers freed in %.3f ms, devices destroyed in %.3f ms\n",
                         std::chrono::duration<double, std::milli>(t1 - t0).count(), core::msSince(t1));
    }

    // Devices are opened one after the other: opened at once (two H200s,
    // driver 580), the drivers' device creation waited on each other (the
    // first device's choice took 418 ms beside the second's VkDevice) and one
    // process of three never finished opening them (session 21,
    // docs/bench/scale).
    [[nodiscard]] std::optional<Error> open(const VulkanDevice* borrowed) {
        if (auto err = openDevice(m_options, m_options.backend, m_options.deviceIndex, first(), borrowed))
            return err;
        m_kind = first().context->backend();
        m_name = first().context->deviceName();
        for (size_t i = 1; i < m_options.devices.size(); ++i) {
            auto& device = m_lanes.emplace_back(std::make_unique<Device>());
            if (auto err = openDevice(m_options, m_kind, m_options.devices[i], *device, nullptr)) {
                return Error{err->code, "device " + std::to_string(m_options.devices[i]) +
                                            " of EngineOptions::devices: " + err->message};
            }
            m_name += " + " + device->context->deviceName();
        }
        return std::nullopt;
    }

    [[nodiscard]] Backend kind() const override { return m_kind; }
    [[nodiscard]] const std::string& deviceName() const override { return m_name; }

    [[nodiscard]] BackendCaps caps() const override {
        BackendCaps caps;
        caps.scan = gpu().scanLimits();
        caps.ingestPoints = gpu_algo::GpuHausdorff::ingestPoints();
        caps.lanes = int(m_lanes.size());
        caps.piecesOnOutOfMemory = m_options.memoryBudget == 0;
        const bool cpuDevice = first().context->cpuDevice();
        caps.narrowOnHost = m_options.tuning->narrowHostBounds.value_or(cpuDevice);
        caps.narrowedIngest = m_options.tuning->narrowedIngest.value_or(!cpuDevice);
        caps.coresForOwnStrays = m_options.tuning->coresForOwnStrays.value_or(true);
        if (!first().context->borrowed())
            caps.noDeviceViews =
                "device views (DevicePointView) need an Engine created on your VkDevice "
                "(Engine::create(const VulkanDevice&, ...))";
        return caps;
    }

    // The caller's EngineOptions::memoryBudget, else three quarters of the
    // device's budget; set pieces up to the largest allocation the device
    // promises (the smallest device sets the pieces).
    [[nodiscard]] MemoryBudget memoryBudget() const override {
        MemoryBudget budget;
        if (m_options.memoryBudget > 0) {
            budget.bytes = m_options.memoryBudget;
            budget.source = "EngineOptions::memoryBudget";
        } else {
            budget.bytes = UINT64_MAX;
            budget.source = "3/4 of the device's memory budget";
        }
        for (const auto& lane : m_lanes) {
            const gpu::DeviceLimits& limits = lane->context->limits();
            if (m_options.memoryBudget == 0)
                budget.bytes = std::min(budget.bytes, limits.deviceBudgetBytes / 4 * 3);
            budget.maxPiecePoints =
                std::min({budget.maxPiecePoints, limits.maxAllocationBytes / kLargestBufferBytesPerPoint,
                          limits.maxBufferBytes / kLargestBufferBytesPerPoint, limits.maxPrimitives});
        }
        return budget;
    }

    [[nodiscard]] Result<HausdorffResult> computeFramed(int lane, std::span<const glm::vec3> a,
                                                        std::span<const glm::vec3> b, double scale,
                                                        const CallOptions& call,
                                                        const core::PerPointFloor& floor) override {
        return gpu(lane).computeIndexed(a, b, scale, call, floor);
    }
    [[nodiscard]] Result<HausdorffResult> scanFramed(int lane, std::span<const glm::vec3> a,
                                                     std::span<const glm::vec3> b, double scale,
                                                     const CallOptions& call) override {
        return gpu(lane).scanWhole(a, b, scale, call);
    }
    [[nodiscard]] Result<HausdorffResult> computeIngested(
        std::span<const glm::vec3> a, std::span<const glm::vec3> b, const CallOptions& call,
        const std::function<bool(const core::Bounds&, const core::Bounds&)>& leave) override {
        return gpu().computePacked(a, b, call, leave);
    }

    [[nodiscard]] Result<std::shared_ptr<BackendSet>> prepare(std::span<const glm::vec3> floats, double scale,
                                                              int bits, const std::string& name) override {
        Timings timings;
        auto g = gpu().prepare(floats, scale, bits, name, timings);
        if (!g) return g.error();
        return std::shared_ptr<BackendSet>(std::make_shared<GpuSet>(std::move(g.value())));
    }
    [[nodiscard]] Result<HausdorffResult> computePrepared(const BackendSet& a, const BackendSet& b,
                                                          const CallOptions& call) override {
        return gpu().compute(deviceSet(a), deviceSet(b), call);
    }
    [[nodiscard]] std::vector<Result<HausdorffResult>> scanPrepared(std::span<const BackendSetPair> pairs,
                                                                    const CallOptions& call) override {
        std::vector<std::pair<const gpu_algo::DeviceSet*, const gpu_algo::DeviceSet*>> sets;
        for (const auto& [a, b] : pairs) sets.emplace_back(&deviceSet(*a), &deviceSet(*b));
        return gpu().computeSmallPairs(sets, call);
    }

    [[nodiscard]] Result<HausdorffResult> computeDeviceViews(const DevicePointView& a,
                                                             const DevicePointView& b,
                                                             const CallOptions& call) override {
        const VkDevice device = first().context->device();
        return gpu().computeDevice(deviceInputOf(a, device), deviceInputOf(b, device), call);
    }
    [[nodiscard]] Result<DeviceViewSet> prepareDeviceView(const DevicePointView& points,
                                                          const std::optional<glm::dvec3>& origin, int bits,
                                                          const std::string& name) override {
        Timings timings;
        auto g = gpu().prepareDevice(deviceInputOf(points, first().context->device()), origin, bits, name,
                                     timings);
        if (!g) return g.error();
        return DeviceViewSet{std::make_shared<GpuSet>(std::move(g->set)), g->summary, g->origin};
    }

    [[nodiscard]] Result<TriangleCandidates> nearestTriangles(const core::FramedQueries& queries,
                                                              std::span<const glm::vec3> corners,
                                                              const std::atomic<bool>* cancel,
                                                              uint64_t cornersVersion) override {
        auto found = gpu().nearestTriangles(queries, corners, cancel, cornersVersion);
        if (!found) return found.error();
        return TriangleCandidates{std::move(found->triangle),
                                  std::move(found->distance2),
                                  std::move(found->tops),
                                  found->radii,
                                  found->rays,
                                  found->submissions,
                                  found->gpuMs,
                                  found->gpuBuildMs,
                                  found->stageMs,
                                  found->submitMs,
                                  found->readbackMs,
                                  std::move(found->open),
                                  found->tailQueries,
                                  found->tailTreeReused,
                                  found->tailLanes,
                                  found->tailBuildMs,
                                  found->tailGpuMs};
    }

    void releaseScratch() override {
        for (const auto& lane : m_lanes) lane->gpu->releaseScratch();
    }
    void recyclePerPoint(int lane, PerPoint&& a, PerPoint&& b) override {
        gpu(lane).recyclePerPoint(std::move(a), std::move(b));
    }
    [[nodiscard]] uint32_t handedBack() const override { return gpu().handedBack(); }
    [[nodiscard]] uint64_t validationMessages() const override {
        uint64_t n = 0;
        for (const auto& lane : m_lanes) n += lane->context->validationMessageCount();
        return n;
    }
    [[nodiscard]] std::string pipelineCachePath() const override { return gpu().pipelineCachePath(); }
    [[nodiscard]] std::string pipelineCacheStatus() const override { return gpu().pipelineCacheStatus(); }

private:
    [[nodiscard]] Device& first() const { return *m_lanes.front(); }
    [[nodiscard]] gpu_algo::GpuHausdorff& gpu(int lane = 0) const { return *m_lanes[size_t(lane)]->gpu; }

    EngineOptions m_options;
    Backend m_kind = Backend::kAuto;
    std::string m_name;
    // The devices in lane order (out_of_core.hpp): the first, then EngineOptions::devices past it.
    std::vector<std::unique_ptr<Device>> m_lanes = [] {
        std::vector<std::unique_ptr<Device>> lanes;
        lanes.push_back(std::make_unique<Device>());
        return lanes;
    }();
};

}  // namespace

Result<std::unique_ptr<ComputeBackend>> makeGpuBackend(const EngineOptions& options,
                                                       const VulkanDevice* borrowed) {
    auto backend = std::make_unique<GpuBackend>(options);
    if (auto err = backend->open(borrowed)) return *err;
    return std::unique_ptr<ComputeBackend>(std::move(backend));
}

}  // namespace rthdist::api
