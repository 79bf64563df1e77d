// rthdist — exact Hausdorff distance between two 3-D point sets on Vulkan
// ray-tracing hardware (RT-HDIST: Kim, Lee, Kim 2025), with an exact CPU
// backend.
//
// Contract
//   h(A,B) = max_{a in A} min_{b in B} |a - b|,  H(A,B) = max(h(A,B), h(B,A)).
//   The value is EXACT for the input as the caller gave it (float or double,
//   point_view.hpp): it equals the brute force computed in double over those
//   coordinates within 1e-6 of the diagonal D of the union's bounding box
//   (the extent, not the magnitude of the coordinates), and the reported
//   index pair realizes it. Final distances and witness points come from the
//   original coordinates, in double.
//
// Precision (DESIGN §8): when an input is double, both sets are shifted by
//   one origin o chosen in double (the centre of the union's bounding box,
//   HausdorffResult::origin) and the search runs on p - o rounded to float32.
//   Each coordinate then moves by at most 2^-24 * D / 2, so every distance by
//   at most eps = sqrt(3) * 2^-24 * D (about 1e-7 D) and the float search
//   finds, for every query, a neighbour within 2 eps of its true nearest
//   neighbour: the reported h is within 2 eps (< 1e-6 D) of the double truth,
//   realized by a real pair, for coordinates of any magnitude (UTM, ECEF).
//   Inputs whose every coordinate is a float32 value (float views, and double
//   views holding float values, e.g. text written from floats) are searched
//   as they are (o = 0). Squared distances that would overflow or vanish in float
//   are handled by an exact power-of-two scale (algo::exactScale).
//
// Inputs: PointView (float or double, any stride; spans and vectors of
//   glm::vec3 or glm::dvec3 convert), finite coordinates (NaN/Inf -> kInvalidArgument),
//   at least one point per side (an empty set -> kInvalidArgument; H is
//   undefined). Up to 2^31 - 1 points per side (more -> kInvalidArgument);
//   a buffer past the device's maxBufferSize, a BLAS past maxPrimitiveCount
//   or a failed allocation -> kOutOfMemory naming the limit (README, limits).
//   Dispatches and traces are split by the device's limits.
//
// Self-check (GPU backends, every call): the index of each set is a
//   permutation under its own cell keys, every query ends exact or dominated
//   below the final maximum, sampled device records and the witness agree
//   with the input points, and h is not below its witness-less lower bound.
//   A failure returns kInternal with the reason instead of a value.
//
// Threading: an Engine owns one Vulkan device and is not thread-safe; use one
//   Engine per thread. The free function hausdorff() creates a temporary
//   Engine (device + pipelines) per call: embedders that call repeatedly
//   should keep an Engine.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist {

enum class Backend {
    kAuto,        // a hardware RT device: ray-query if it has it, else rt-pipeline;
                  // no such device (none, or only a software one such as
                  // lavapipe): the CPU backend, which is faster there
    kRayQuery,    // VK_KHR_ray_query in compute shaders
    kRtPipeline,  // VK_KHR_ray_tracing_pipeline (raygen + intersection)
    kCpu,         // exact multithreaded CPU implementation (no Vulkan)
};

[[nodiscard]] RTHDIST_API const char* backendName(Backend backend);
// Parses "auto", "ray-query", "rt-pipeline", "cpu"; false when unknown.
[[nodiscard]] RTHDIST_API bool parseBackend(const std::string& text, Backend& out);

struct Options {
    Backend backend = Backend::kAuto;
    // Index-space bit count k (cells of edge L / 2^k). 0 = choose from the
    // data (about kTargetPointsPerCell target points per occupied cell).
    int bits = 0;
    // true: compute only h(A,B); b_to_a is left empty.
    bool directedOnly = false;
    // Vulkan physical device index as listed by listDevices(); -1 = first usable.
    int deviceIndex = -1;
    // Enable VK_LAYER_KHRONOS_validation and count every message it emits
    // (Result::validationMessages). For tests; slow.
    bool validation = false;
    // Radius growth factor between candidate-search iterations (> 1).
    float radiusGrowth = 2.0f;
    // CPU backend threads; 0 = all hardware threads.
    int threads = 0;
    // Also return every point's exact nearest-neighbour distance and index
    // (HausdorffResult::aNearest / bNearest). Every query then needs its own
    // NN, so the early break against the running maximum is off: slower.
    bool perPointDistances = false;
    // Called from the calling thread between stages and iterations with a
    // stage name ("index", "cull", "search", "refine") and the fraction of
    // the whole call done so far (0..1). Must not throw.
    std::function<void(const char* stage, double fraction)> progress;
};

// Every point's nearest neighbour in the other set (perPointDistances).
struct PerPoint {
    std::vector<double> distance;   // recomputed in double from the pair
    std::vector<uint32_t> nearest;  // index of the nearest point in the other set
};

// Counters of one direction: what the algorithm did.
struct Counters {
    uint32_t bits = 0;                   // k actually used for the target index
    uint64_t occupiedCells = 0;          // occupied cells of the target index
    uint64_t queries = 0;                // query points
    uint64_t culledByNeighbourhood = 0;  // queries resolved before any ray
    uint64_t survivingQueries = 0;       // queries that entered candidate search
    uint32_t iterations = 0;             // candidate-search radius iterations
    uint64_t rays = 0;                   // rays cast over all iterations
    uint64_t candidatePairs = 0;         // (query, cell) pairs refined
};

// One directed distance h(Q,T) with its witness.
struct Directed {
    double distance = 0.0;       // recomputed in double from the pair
    uint32_t queryIndex = 0;     // index into the query set
    uint32_t targetIndex = 0;    // index into the target set (its nearest point)
    glm::dvec3 queryPoint{0.0};  // the input's coordinates (double; exact for float input)
    glm::dvec3 targetPoint{0.0};
    Counters counters;
};

// Wall-clock milliseconds per stage, summed over both directions.
struct Timings {
    double setup = 0.0;   // device/pipeline creation (0 when an Engine is reused)
    double upload = 0.0;  // host -> device copies
    double index = 0.0;   // stage 1: bounding box, cell keys, sort, run-length encode
    double cull = 0.0;    // neighbourhood pass: exact NN in the 3x3x3 cell block
    double search = 0.0;  // stage 2: BLAS builds + ray traversal (candidate pairs)
    double refine = 0.0;  // stage 3: exact scan of candidate cells, classification
    double check = 0.0;   // GPU backends: the witness read-back with the per-query self-check
                          // (one submission per direction); the index self-check runs inside
                          // `index`. 0 on the CPU backend
    double total = 0.0;   // the whole compute() call, device setup excluded
    // Device time per stage from Vulkan timestamp queries (GPU backends only;
    // 0 on the CPU backend). The wall-clock fields above include submission,
    // waiting and the host work between the stages' submissions.
    double gpuIndex = 0.0;
    double gpuCull = 0.0;
    double gpuSearch = 0.0;
    double gpuRefine = 0.0;
};

struct HausdorffResult {
    double hausdorff = 0.0;  // max of both directions (or h(A,B) when directed)
    Directed aToB;
    Directed bToA;      // empty when Options::directedOnly
    PerPoint aNearest;  // A's points -> B, with Options::perPointDistances
    PerPoint bNearest;  // B's points -> A (unless directedOnly)
    bool directedOnly = false;
    Backend backend = Backend::kAuto;  // the backend that ran
    std::string device;                // device name, or "cpu"
    // Subtracted from both sets before the float32 search: 0 when every
    // coordinate is a float32 value, else the centre of the union's box.
    glm::dvec3 origin{0.0};
    Timings timings;
    uint64_t validationMessages = 0;  // with Options::validation
};

// A Vulkan physical device and what rthdist can do with it.
struct DeviceInfo {
    int index = 0;
    std::string name;
    std::string type;  // "discrete", "integrated", "cpu", "virtual", "other"
    std::string driver;
    bool rayQuery = false;             // the ray-query backend can run
    bool rtPipeline = false;           // the rt-pipeline backend can run
    std::vector<std::string> missing;  // why a backend is unusable
    // The size limits rthdist checks every problem against (README, limits):
    // max_buffer_bytes, max_allocation_bytes, device_heap_bytes,
    // host_heap_bytes, max_work_groups_x, max_ray_dispatch, max_blas_primitives.
    std::vector<std::pair<std::string, uint64_t>> limits;
};

// Lists every Vulkan device; an error only when no Vulkan loader/ICD works.
[[nodiscard]] RTHDIST_API Result<std::vector<DeviceInfo>> listDevices();

// Owns a Vulkan device, its pipelines and scratch memory between calls.
class RTHDIST_API Engine {
public:
    [[nodiscard]] static Result<Engine> create(const Options& options);
    Engine(Engine&&) noexcept;
    Engine& operator=(Engine&&) noexcept;
    ~Engine();

    [[nodiscard]] Result<HausdorffResult> compute(PointView a, PointView b);
    [[nodiscard]] const std::string& deviceName() const;
    [[nodiscard]] Backend backend() const;

    struct Impl;

private:
    // The one-shot entry validates its inputs itself and calls the engine's
    // core directly, so the points are scanned once.
    friend RTHDIST_API Result<HausdorffResult> hausdorff(PointView a, PointView b, const Options& options);

    explicit Engine(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

// One-shot convenience: creates an Engine (or runs the CPU backend) and computes.
[[nodiscard]] RTHDIST_API Result<HausdorffResult> hausdorff(PointView a, PointView b,
                                                            const Options& options = {});

RTHDIST_API const char* versionString();

}  // namespace rthdist
