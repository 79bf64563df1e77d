// The backend interface's optional methods (a backend whose caps() never
// plan their route leaves them) and the choice of the Engine's backend.
#include "api/backend.hpp"

#include <string>

#include "core/stopwatch.hpp"
#include "rthdist/tuning.hpp"

namespace rthdist::api {

namespace {

Error notOffered(const char* what) {
    return Error{ErrorCode::kInternal, std::string("the backend offers no ") + what +
                                           " (the route planner chose a route outside its caps)"};
}

// auto picks a Vulkan backend only on a device with RT hardware paths that is
// not a software rasterizer: on lavapipe (VK_PHYSICAL_DEVICE_TYPE_CPU) the
// native CPU backend is 10-100x faster (docs/bench). A device named
// (deviceIndex, devices) or validation asked for keeps the Vulkan path on
// whatever device that is (README, --backend): a named device without an RT
// path is then the GPU backend's error, not a silent CPU run, and
// validation validates a Vulkan device (it ran the CPU backend on lavapipe,
// reporting "validation": true and 0 messages).
bool hardwareRtDevice(const EngineOptions& o) {
    if (o.deviceIndex >= 0 || !o.devices.empty() || o.validation) return true;
    auto devices = listDevices();
    if (!devices) return false;
    for (const DeviceInfo& d : devices.value()) {
        if ((d.rayQuery || d.rtPipeline) && d.type != "cpu") return true;
    }
    return false;
}

}  // namespace

Result<HausdorffResult> ComputeBackend::scanFramed(int, std::span<const glm::vec3>,
                                                   std::span<const glm::vec3>, double, const CallOptions&) {
    return notOffered("small-pair scan");
}

Result<HausdorffResult> ComputeBackend::computeIngested(
    std::span<const glm::vec3>, std::span<const glm::vec3>, const CallOptions&,
    const std::function<bool(const core::Bounds&, const core::Bounds&)>&) {
    return notOffered("device ingest");
}

std::vector<Result<HausdorffResult>> ComputeBackend::scanPrepared(std::span<const BackendSetPair> pairs,
                                                                  const CallOptions&) {
    return std::vector<Result<HausdorffResult>>(pairs.size(), notOffered("small-pair scan"));
}

Result<HausdorffResult> ComputeBackend::computeDeviceViews(const DevicePointView&, const DevicePointView&,
                                                           const CallOptions&) {
    return notOffered("device views");
}

Result<TriangleCandidates> ComputeBackend::nearestTriangles(const core::FramedQueries&,
                                                            std::span<const glm::vec3>,
                                                            const std::atomic<bool>*, uint64_t) {
    return notOffered("triangle search");
}

Result<DeviceViewSet> ComputeBackend::prepareDeviceView(const DevicePointView&,
                                                        const std::optional<glm::dvec3>&, int,
                                                        const std::string&) {
    return notOffered("device views");
}

Result<std::unique_ptr<ComputeBackend>> openBackend(const EngineOptions& options,
                                                    const VulkanDevice* borrowed) {
    if (borrowed) {
        if (options.backend == Backend::kCpu)
            return Error{ErrorCode::kInvalidArgument,
                         "the cpu backend takes no Vulkan device (VulkanDevice)"};
        return makeGpuBackend(options, borrowed);
    }
    if (options.backend == Backend::kCpu ||
        (options.backend == Backend::kAuto && !hardwareRtDevice(options))) {
        if (options.devices.size() > 1) {  // (auto with devices named takes the GPU path)
            return Error{ErrorCode::kInvalidArgument,
                         "several devices (EngineOptions::devices) need a GPU backend; the cpu backend was "
                         "asked for"};
        }
        return makeCpuBackend(options);
    }
    return makeGpuBackend(options, nullptr);
}

std::future<OneShotBackend> openOneShot(Backend backend, int deviceIndex, bool validation, int threads) {
    return std::async(std::launch::async, [=] {
        const core::Clock::time_point start = core::Clock::now();
        EngineOptions engine;
        engine.backend = backend;
        engine.deviceIndex = deviceIndex;
        engine.validation = validation;
        engine.threads = threads;
        engine.tuning = tuningFromEnvironment();
        OneShotBackend out;
        out.backend = openBackend(engine, nullptr);
        out.ms = core::msSince(start);
        return out;
    });
}

}  // namespace rthdist::api
