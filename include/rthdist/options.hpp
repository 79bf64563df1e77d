// rthdist — settings: what an Engine owns (EngineOptions: device, backend,
// validation, host threads) and what each call may change without a new
// Engine (CallOptions: bit count, direction, per-point output, radius
// growth, progress, cancellation). Options holds both, for the one-shot
// hausdorff() and for callers of the first releases.
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/tuning.hpp"

namespace rthdist {

enum class Backend {
    kAuto,        // a hardware RT device: ray-query if it has it, else rt-pipeline;
                  // no such device (none, or only a software one such as
                  // lavapipe): the CPU backend, which is faster there; a
                  // one-shot call of a small pair: the CPU backend too
                  // (oneShotBackendFor, rthdist.hpp). A device named
                  // (deviceIndex, devices) or validation keeps the Vulkan
                  // path on that device, software or not
    kRayQuery,    // VK_KHR_ray_query in compute shaders
    kRtPipeline,  // VK_KHR_ray_tracing_pipeline (raygen + intersection)
    kCpu,         // exact multithreaded CPU implementation (no Vulkan)
};

[[nodiscard]] RTHDIST_API const char* backendName(Backend backend);
// Parses "auto", "ray-query", "rt-pipeline", "cpu"; false when unknown.
[[nodiscard]] RTHDIST_API bool parseBackend(const std::string& text, Backend& out);

// Fixed for the life of an Engine (its device and pipelines).
// The most entries of EngineOptions::devices: each opens a Vulkan device
// (about 20 MB of host memory and 50-80 ms on lavapipe), so the list is
// bounded; 16 covers the largest single hosts (16 GPUs).
inline constexpr size_t kMaxEngineDevices = 16;

struct EngineOptions {
    Backend backend = Backend::kAuto;
    // Vulkan physical device index as listed by listDevices(); -1 = the first
    // usable discrete GPU, else integrated, virtual, other, software last.
    // An index the list does not hold is kNoDevice on every backend but
    // kCpu (Backend::kAuto included; so is such an entry of `devices`).
    int deviceIndex = -1;
    // Several devices (listDevices() indices) for one Engine, GPU backends
    // only. A one-shot compute(a, b) past the memory budget (out of core)
    // spreads its pieces over the devices: each direction's query chunks (at
    // least one per device) are taken by the devices in parallel, each
    // indexing the targets (or the tiles) it needs, the early break shared
    // between chunks; the result, witnesses included, is the one-device
    // result (README, "Several GPUs"). A pair that fits one call runs on the
    // first device (splitting it costs more than it gains: each device would
    // index every target), as do prepared sets and batches. Empty:
    // deviceIndex alone. At most kMaxEngineDevices entries (more ->
    // kInvalidArgument before any device is opened). An index given twice
    // opens that device twice (tests on a one-device machine; no speedup);
    // the CLI's --devices refuses a repeated index. Every device must run the
    // backend.
    std::vector<int> devices;
    // Enable VK_LAYER_KHRONOS_validation and count every message it emits
    // (Result::validationMessages). For tests; slow.
    bool validation = false;
    // Host threads: the CPU backend's, and the GPU backends' passes over the
    // points (checks, bounds, copies); 0 = all hardware threads. The work
    // runs on one persistent worker pool per process (core/thread_pool),
    // whose waiting threads poll for up to 200 us before they sleep
    // (Tuning::poolSpinMicros sets it; 0: never).
    int threads = 0;
    // GPU backends: the directory of the pipeline cache file, which spares a
    // new process the pipeline compilation on the same device and driver.
    // Empty: Tuning::pipelineCacheDir ($RTHDIST_CACHE_DIR, else
    // $XDG_CACHE_HOME/rthdist, else $HOME/.cache/rthdist); "off": no file. A missing, foreign or damaged
    // file only means compiling again (Engine::pipelineCacheStatus).
    std::string pipelineCacheDir;
    // Every knob that is not an option (rthdist/tuning.hpp): the search's
    // radius schedule, the small-pair limit, polling, diagnostics. Empty:
    // tuningFromEnvironment() when the Engine is created.
    std::optional<Tuning> tuning;
    // Out-of-core: the memory one backend call may hold, in bytes. A pair of
    // sets larger than that is computed exactly as a sequence of calls over
    // query chunks and target tiles (README, "Inputs larger than the
    // device"; Counters::queryChunks/targetTiles). 0 = automatic: on the GPU
    // backends three quarters of the device-local heap's budget
    // (VK_EXT_memory_budget where the device has it, else the heap's size),
    // with no set piece past maxMemoryAllocationSize / 32 points; on the CPU
    // backend no limit. Set it to leave device memory to other work, or to
    // force the split (tests use a few MB). Prepared sets are not split: a
    // set that does not fit is refused by prepare() (kOutOfMemory).
    uint64_t memoryBudget = 0;
};

// Settings of one compute call: changing one never rebuilds a device,
// pipelines or a prepared set.
struct CallOptions {
    // Index-space bit count k (cells of edge L / 2^k) of the sets indexed by
    // this call. 0 = choose from the data (about kTargetPointsPerCell target
    // points per occupied cell). A prepared set keeps the bit count it was
    // prepared with (PrepareOptions::bits); this field does not re-index it.
    int bits = 0;
    // true: compute only h(A,B); b_to_a is left empty.
    bool directedOnly = false;
    // Radius growth factor between candidate-search iterations (> 1).
    float radiusGrowth = 2.0f;
    // Also return every point's nearest-neighbour distance and index
    // (HausdorffResult::aNearest / bNearest), core::exactDistance in double
    // of the pair: for double inputs the exact nearest (minimal over every
    // point of the other set, the smallest index on a tie: the float
    // search's pairs made exact on the host); for float32 inputs the float
    // search's pair, at most a relative 2^-21 above the exact nearest
    // distance; device views keep the float pairs, within 2e (README
    // "Per-point distances"). Every query then needs its own NN, so the
    // early break against the running maximum is off: slower.
    bool perPointDistances = false;
    // With perPointDistances: fill only PerPoint::nearest, leaving
    // PerPoint::distance empty, for callers that recompute each distance in
    // a metric of their own (the segmentation masks do, from voxel
    // indices). On the GPU backends it spares the host's pass over every
    // query's pair; the CPU backend computes the distances for its witness
    // and drops them. Ignored without perPointDistances.
    bool perPointNearestOnly = false;
    // With perPointDistances and perPointNearestOnly (else the call is
    // refused, kInvalidArgument): called once per computed direction
    // (0: A's points -> B, 1: B's -> A) with that direction's
    // PerPoint::nearest — the very array the result returns — as soon as it
    // is final, so that a caller's own work on one direction overlaps the
    // search of the other. Engine::compute calls only; computeBatch ignores
    // it. On the GPU backends the direction with more query points is then
    // searched first and handed to a thread of the call's own while the
    // device searches the other one; every other path (the CPU backend,
    // pairs split into pieces, small pairs scanned whole) calls it from the
    // calling thread once the result is complete. Either way compute()
    // returns (a result or an error) only after every call of it has
    // returned; a call that fails may have handed back some directions or
    // none (and one that ran out of device memory after handing a direction
    // back returns kOutOfMemory instead of retrying in pieces). Must not
    // throw and must not call back into the Engine; it may run the
    // library's host threads (it shares their pool).
    std::function<void(int direction, std::span<const uint32_t> nearest)> perPointReady;
    // Called from the calling thread between stages and iterations with a
    // stage name ("index", "cull", "search", "refine") and the fraction of
    // the whole call done so far (0..1); a pair scanned whole (small pairs on
    // a GPU backend: Engine::computeBatch) reports "search" once, before its
    // submission. Must not throw.
    std::function<void(const char* stage, double fraction)> progress;
    // Cancellation: when the flag (owned by the caller, settable from any
    // thread or from `progress`) reads true at a stage boundary, a search
    // iteration or a percent of the CPU search, the call returns
    // ErrorCode::kCancelled and leaves the Engine and prepared sets usable.
    const std::atomic<bool>* cancel = nullptr;
};

// How a set is prepared (Engine::prepare).
struct PrepareOptions {
    // Bit count of the set's index (0 = from the data).
    int bits = 0;
    // Frame of a double set whose coordinates are not all float32 values
    // (design.md §8): it is searched as p - origin rounded to float. Unset: the
    // centre of its own box. Two prepared sets reuse their indexes together
    // only when they share a frame: give the sets that will meet one origin
    // (say reference.origin()). Float sets (and double sets of float values)
    // are searched as they are: origin 0, this field ignored.
    std::optional<glm::dvec3> origin;
};

// Both kinds, for hausdorff() and Engine::create(const Options&) (whose
// compute(a, b) uses the call settings given here).
struct Options : EngineOptions, CallOptions {};

}  // namespace rthdist
