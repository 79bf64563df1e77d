// The backend interface of the Engine: what the CPU backend (src/cpu) and
// the GPU algorithm (src/gpu_algo, on one or more devices) do for a call, in
// one shape, so that engine.cpp runs the planner's route
// (api/route_planner.hpp) with no branch on the backend. The frame (origin,
// float rounding, exact scale) is entered and left in engine.cpp: every
// method here takes float sets already in it and hands back witnesses by
// input index, distances of the framed floats (the Engine restores them).
//
// Adapters: cpu_backend.cpp (Backend::kCpu) and gpu_backend.cpp (the Vulkan
// backends); openBackend picks one.
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "api/out_of_core.hpp"
#include "api/route_planner.hpp"
#include "core/framed_queries.hpp"
#include "core/input_frame.hpp"
#include "core/per_point_floor.hpp"
#include "core/searched_tops.hpp"
#include "core/uninit_vector.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace rthdist::api {

// A set prepared by a backend (its index or order), kept by a PreparedSet.
class BackendSet {
public:
    virtual ~BackendSet() = default;
    [[nodiscard]] virtual int bits() const = 0;
    [[nodiscard]] virtual uint64_t deviceBytes() const = 0;
    [[nodiscard]] virtual uint64_t hostBytes() const = 0;
};

// A set prepared from a device view, with the frame the device chose.
struct DeviceViewSet {
    std::shared_ptr<BackendSet> set;
    core::SetSummary summary;
    glm::dvec3 origin{0.0};
};

using BackendSetPair = std::pair<const BackendSet*, const BackendSet*>;

// The point-to-surface search of a backend that searches in float
// (design.md §11): every query's nearest triangle as it found it
// (UINT32_MAX: none), a candidate the caller proves in double
// (api/surface_certify.hpp).
struct TriangleCandidates {
    core::UninitVector<uint32_t> triangle;
    core::UninitVector<float>
        distance2;             // the device's squared distance to `triangle` (search frame), +inf for none
    core::SearchedTops tops;   // distance2's largest by chunks (may be empty: chunk 0)
    uint32_t radii = 0;        // radii searched
    uint64_t rays = 0;         // rays cast
    uint32_t submissions = 0;  // command buffers submitted and waited for
    double gpuMs = 0.0;        // device time
    double gpuBuildMs = 0.0;   // of which the boxes and BLAS builds and refits
    double stageMs = 0.0;      // host: the upload buffer written
    double submitMs = 0.0;     // host wall of the submissions (upload copies, radii, read-back copy)
    double readbackMs = 0.0;   // host: the candidates read back
    // Queries the radii left open, where few: no tail searched them; the
    // caller measures them exactly (api/surface_certify.hpp). In index order.
    std::vector<uint32_t> open;
    uint64_t tailQueries = 0;     // queries the tail's tree descent searched (left open by the radii)
    bool tailTreeReused = false;  // the tail's tree was the call before's (the same corners)
    uint32_t tailLanes = 0;       // threads a query of the tail's descent
    double tailBuildMs = 0.0;     // host: the tail's tree built and written (part of submitMs)
    double tailGpuMs = 0.0;       // device time of the tail (part of gpuMs)
};

class ComputeBackend {
public:
    virtual ~ComputeBackend() = default;

    [[nodiscard]] virtual Backend kind() const = 0;
    [[nodiscard]] virtual const std::string& deviceName() const = 0;
    // What the planner needs to know of it.
    [[nodiscard]] virtual BackendCaps caps() const = 0;
    // What one call may hold (out_of_core.hpp): the caller's
    // EngineOptions::memoryBudget, else the devices'.
    [[nodiscard]] virtual MemoryBudget memoryBudget() const = 0;

    // A framed pair in one call on device `lane` (0 .. caps().lanes - 1):
    // indexed (Route::kOneCall and the pieces), or scanned whole
    // (Route::kSmallPairScan; backends whose caps scan no pair need not).
    // `floor`: per-point queries that may stop below it
    // (core/per_point_floor.hpp; the pieces' round one).
    [[nodiscard]] virtual Result<HausdorffResult> computeFramed(int lane, std::span<const glm::vec3> a,
                                                                std::span<const glm::vec3> b, double scale,
                                                                const CallOptions& call,
                                                                const core::PerPointFloor& floor) = 0;
    [[nodiscard]] virtual Result<HausdorffResult> scanFramed(int lane, std::span<const glm::vec3> a,
                                                             std::span<const glm::vec3> b, double scale,
                                                             const CallOptions& call);
    // Route::kDeviceIngest: packed float arrays in their own coordinates
    // (origin 0), checked by the device. `leave`, when given, sees both
    // sets' bounds before any index is built; true ends the call with an
    // empty result (the engine takes the narrowed route instead).
    [[nodiscard]] virtual Result<HausdorffResult> computeIngested(
        std::span<const glm::vec3> a, std::span<const glm::vec3> b, const CallOptions& call,
        const std::function<bool(const core::Bounds&, const core::Bounds&)>& leave = {});

    // A set of floats (before the exact power of two `scale`) indexed once;
    // `floats` must outlive the set; `name` labels its buffers.
    [[nodiscard]] virtual Result<std::shared_ptr<BackendSet>> prepare(std::span<const glm::vec3> floats,
                                                                      double scale, int bits,
                                                                      const std::string& name) = 0;
    // Route::kPrepared: two sets of this backend, one frame and scale.
    [[nodiscard]] virtual Result<HausdorffResult> computePrepared(const BackendSet& a, const BackendSet& b,
                                                                  const CallOptions& call) = 0;
    // Route::kSmallPairScan of prepared sets: every pair in one submission
    // (witnesses by input index, distances of the framed floats).
    [[nodiscard]] virtual std::vector<Result<HausdorffResult>> scanPrepared(
        std::span<const BackendSetPair> pairs, const CallOptions& call);

    // Route::kDeviceViews and sets prepared from device views (caps().noDeviceViews
    // empty), of views that passed api::checkDeviceView (device_views.hpp: the
    // Engine checks each view once, before the backend sees it).
    [[nodiscard]] virtual Result<HausdorffResult> computeDeviceViews(const DevicePointView& a,
                                                                     const DevicePointView& b,
                                                                     const CallOptions& call);
    [[nodiscard]] virtual Result<DeviceViewSet> prepareDeviceView(const DevicePointView& points,
                                                                  const std::optional<glm::dvec3>& origin,
                                                                  int bits, const std::string& name);

    // Route::kSurfaceGpu: queries and triangle corners (3 per triangle) in
    // one float frame, on the first device; `cancel` read between
    // submissions (kCancelled). What it allocates stays for the next call
    // (releaseScratch frees it).
    // cornersVersion: 0, or the caller's name for these very corners
    // (newCornersVersion), never given to other corners: the device then
    // keeps what it built from them without comparing them again.
    [[nodiscard]] virtual Result<TriangleCandidates> nearestTriangles(const core::FramedQueries& queries,
                                                                      std::span<const glm::vec3> corners,
                                                                      const std::atomic<bool>* cancel,
                                                                      uint64_t cornersVersion);

    // Frees what every lane keeps between one-shot calls (out_of_core.hpp's `release`).
    virtual void releaseScratch() {}
    // Hands a result's per-point arrays back to lane `lane` for its next call.
    virtual void recyclePerPoint(int /*lane*/, PerPoint&& /*a*/, PerPoint&& /*b*/) {}
    // CallOptions::perPointReady directions the last call handed back itself (bit k: direction k).
    [[nodiscard]] virtual uint32_t handedBack() const { return 0; }
    // Vulkan validation messages over every device so far.
    [[nodiscard]] virtual uint64_t validationMessages() const { return 0; }
    [[nodiscard]] virtual std::string pipelineCachePath() const { return {}; }
    [[nodiscard]] virtual std::string pipelineCacheStatus() const { return "none"; }
};

// The Engine's backend: the CPU one, or the GPU algorithm on the devices of
// `options` (or on the embedder's device `borrowed`). `options.tuning` is set.
[[nodiscard]] Result<std::unique_ptr<ComputeBackend>> openBackend(const EngineOptions& options,
                                                                  const VulkanDevice* borrowed);

// The backend of a one-shot surface call (hausdorffToSurface,
// surfaceHausdorff on a GPU backend): an Engine's options from the call's,
// the tuning from the environment, opened by openBackend on a thread of its
// own while the caller checks the inputs; `ms` the time it took.
struct OneShotBackend {
    Result<std::unique_ptr<ComputeBackend>> backend = Error{ErrorCode::kInternal, "not opened"};
    double ms = 0.0;
};
[[nodiscard]] std::future<OneShotBackend> openOneShot(Backend backend, int deviceIndex, bool validation,
                                                      int threads);

[[nodiscard]] std::unique_ptr<ComputeBackend> makeCpuBackend(const EngineOptions& options);
[[nodiscard]] Result<std::unique_ptr<ComputeBackend>> makeGpuBackend(const EngineOptions& options,
                                                                     const VulkanDevice* borrowed);

}  // namespace rthdist::api
