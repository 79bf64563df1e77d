// rthdist — exact Hausdorff distance between two 3-D point sets on Vulkan
// ray-tracing hardware (RT-HDIST: Kim, Lee, Kim 2025), with an exact CPU
// backend.
//
// Contract
//   h(A,B) = max_{a in A} min_{b in B} |a - b|,  H(A,B) = max(h(A,B), h(B,A)).
//   The value is EXACT for the input as the caller gave it (float or double,
//   point_view.hpp): it equals the brute force computed in double over those
//   coordinates, sqrt(dx^2 + dy^2 + dz^2) (ties aside: among equal values
//   the witness may be another realizing pair), and the reported index pair
//   realizes it. Final distances and witness points come from the original
//   coordinates, in double. Each directed value carries its proof
//   (Directed::certificate, below): the search runs in float32; the queries
//   whose float value lies within the rounding slack e of the float maximum
//   are settled again in double by a brute force over the whole target set.
//   Precondition of the proof: every query ended settled with a real target
//   (the self-check below); a proof that fails makes the Engine recompute
//   the direction on the CPU backend (Certificate::recomputed), and kInternal
//   only if that proof fails too.
//
// Precision (design.md §8): when an input is double, both sets are shifted by
//   one origin o chosen in double (the centre of the union's bounding box,
//   HausdorffResult::origin) and the search runs on p - o rounded to float32.
//   Each coordinate then moves by at most 2^-24 * m (m the largest |p - o|),
//   so every float distance lies within e = 2^-20 m of the exact one (the
//   rounding, the float arithmetic and a margin: core/certificate.hpp). The
//   certificate settles in double every query within 2e of the float
//   maximum, so the reported h is the double truth for coordinates of any
//   magnitude (UTM, ECEF). The band is small on ordinary data: a query
//   enters it only when its nearest distance lies within 2e (~1e-6 of the
//   extent) of h; a maximum below e over more than 2^18 queries (e.g. a set
//   against a copy of itself in a double frame) is settled by the CPU
//   backend's recomputation instead.
//   Inputs whose every coordinate is a float32 value (float views, and double
//   views holding float values, e.g. text written from floats) are searched
//   as they are (o = 0). Squared distances that would overflow or vanish in float
//   are handled by an exact power-of-two scale (core::exactScale).
//
// Inputs: PointView (float or double, any stride; spans and vectors of
//   glm::vec3 or glm::dvec3 convert), finite coordinates (NaN/Inf -> kInvalidArgument),
//   at least one point per side (an empty set -> kInvalidArgument; H is
//   undefined). Up to 2^40 points per side in one-shot calls: sets past
//   2^31 - 1 points (the backends' 32-bit indices) or past the memory budget
//   run in pieces (EngineOptions::memoryBudget), witness indices are 64-bit;
//   per-point output needs both sets below 2^32 points and a prepared set at
//   most 2^31 - 1 (more -> kInvalidArgument). A buffer past the device's
//   maxBufferSize, a BLAS past maxPrimitiveCount or a failed allocation ->
//   kOutOfMemory naming the limit (README, limits).
//   Dispatches and traces are split by the device's limits. Point sets that
//   already lie in an embedding application's VkBuffers: vulkan_interop.hpp
//   (Engine::create(const VulkanDevice&, ...), DevicePointView).
//
// Self-check (GPU backends, every call): the index of each set is a
//   permutation under its own cell keys, every query ends exact or dominated
//   below the final maximum, sampled device records and the witness agree
//   with the input points, and h is not below its witness-less lower bound.
//   A failure returns kInternal with the reason instead of a value.
//
// Threading: an Engine owns one Vulkan device (or several:
//   EngineOptions::devices, whose out-of-core calls run one host thread per
//   device inside the call) and is not thread-safe; use one Engine per
//   thread (with its own prepared sets). The free function
//   hausdorff() creates a temporary Engine (device + pipelines) per call:
//   embedders that call repeatedly should keep an Engine, and prepare the
//   sets they reuse (Engine::prepare).
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
#include "rthdist/options.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist {
namespace detail {
struct ProofMaterial;  // core/certificate.hpp
struct AboveFloor;     // core/per_point_floor.hpp
}  // namespace detail

// Every point's nearest neighbour in the other set (perPointDistances).
struct PerPoint {
    std::vector<double> distance;   // recomputed in double from the pair
    std::vector<uint32_t> nearest;  // index of the nearest point in the other set (which has
                                    // < 2^32 points: per-point output is refused past it)
};

// Counters of one direction: what the algorithm did.
struct Counters {
    uint32_t bits = 0;                   // k actually used for the target index
    uint64_t occupiedCells = 0;          // occupied cells of the target index
    uint64_t queries = 0;                // query points
    uint64_t culledByNeighbourhood = 0;  // queries resolved before any ray
    uint64_t survivingQueries = 0;       // queries that entered candidate search
    uint32_t iterations = 0;             // candidate-search radius iterations (each retry class's turn one)
    uint64_t rays = 0;                   // rays cast over all iterations (a retry class's turn: every
                                         // open query, its class's cast and the others waiting)
    uint64_t candidatePairs = 0;         // (query, cell) pairs refined
    uint64_t tailScanned = 0;            // GPU backends: queries of the search's far tail that
                                         // scanned whole cells of a coarse level instead of more radii
    // Out-of-core (EngineOptions::memoryBudget): how this direction was
    // split; 1 x 1 when it fit one call. Targets that fit one call beside a
    // chunk: queryChunks chunks of queries, each against every target
    // (targetTiles 1). Otherwise pieces ordered in space: the pieces holding
    // queries and those holding targets, and crossPieceQueries, the queries
    // sent to another piece's targets after their own (near a piece's border).
    uint32_t queryChunks = 1;
    uint32_t targetTiles = 1;
    uint64_t crossPieceQueries = 0;
    // Host views: the targets this direction searched when they were
    // narrowed to those within reach of its queries (a cluster beside far
    // strays in the other set: README "Far strays"); 0 when it searched all.
    uint64_t narrowedTargets = 0;
    // Per-point calls: the entries whose nearest target the exact pass
    // changed (the float search's pair was not the nearest in double, or
    // not the smallest index among equally near ones: README "Per-point
    // distances"); 0 without per-point output, and where the caller's
    // coordinates are on a device (no pass).
    uint64_t perPointMended = 0;
};

// The proof of one directed value (README "Exactness"; docs/design.md, "The
// certificate"). The float search leaves every query settled with a real
// nearest-so-far target; the queries whose float value lies within the
// rounding slack e of the float maximum (the band: usually the witness alone)
// get their nearest target by a brute force in double over the WHOLE target
// set (on the device, or on the host for the CPU backend); when the largest of
// those exact distances reaches the float maximum minus e, no other query can
// exceed it, so it is h(Q,T) exactly in double, and its pair is the witness.
// e = 2^-20 * m, m the largest |coordinate| searched (after the frame's origin
// and power-of-two scale), covers every float rounding of the search.
struct Certificate {
    bool confirmed = false;   // the argument held for this answer: distance is exact in double
    bool recomputed = false;  // the first answer's proof failed; the direction was recomputed on
                              // the CPU backend (an independent search), whose proof held
    uint64_t query = 0;       // the witness query (= Directed::queryIndex)
    uint64_t nearest = 0;     // its nearest target by the brute force in double (= targetIndex)
    double distance = 0.0;    // their distance in double (= Directed::distance)
    uint64_t band = 0;        // queries settled again in double
    std::string failure;      // with `recomputed`: why the first answer's proof failed
};

// One directed distance h(Q,T) with its witness.
struct Directed {
    double distance = 0.0;       // recomputed in double from the pair
    uint64_t queryIndex = 0;     // index into the query set (64-bit: one-shot sets may exceed 2^32)
    uint64_t targetIndex = 0;    // index into the target set (its nearest point)
    glm::dvec3 queryPoint{0.0};  // the input's coordinates (double; exact for float input)
    glm::dvec3 targetPoint{0.0};
    Counters counters;
    Certificate certificate;
};

// Wall-clock milliseconds per stage, summed over both directions.
struct Timings {
    double setup = 0.0;        // device/pipeline creation (0 when an Engine is reused)
    double upload = 0.0;       // host -> device copies
    double index = 0.0;        // stage 1: bounding box, cell keys, sort, run-length encode
    double cull = 0.0;         // neighbourhood pass: exact NN in the 3x3x3 cell block
    double search = 0.0;       // stage 2: BLAS builds + ray traversal (candidate pairs)
    double refine = 0.0;       // stage 3: exact scan of candidate cells, classification
    double check = 0.0;        // GPU backends: the per-query self-check (recorded behind the cull,
                               // or behind the search's last radii unless per-point, else a
                               // submission per direction) and the per-point read-back; the index
                               // self-check runs inside `index`. 0 on the CPU backend
    double certificate = 0.0;  // the certificate's brute force and proof in double (wall;
                               // also inside `check`/`total`)
    double pieces = 0.0;       // out of core: the host's own work of the pieces (cutting the
                               // sets in space, merging the calls' results, the proof); narrowed
                               // targets (README "Far strays"): looking for them, the cores and
                               // kept targets, the strays' brute force, the merge; wall
    double total = 0.0;        // the whole compute() call, device setup excluded
    // Device time per stage from Vulkan timestamp queries (GPU backends only;
    // 0 on the CPU backend). The wall-clock fields above include submission,
    // waiting and the host work between the stages' submissions.
    double gpuIndex = 0.0;
    double gpuCull = 0.0;
    double gpuSearch = 0.0;
    double gpuRefine = 0.0;
    // Device time of the host -> device transfers (the copy commands alone;
    // their bytes over this time is the link speed the call reached).
    double gpuUpload = 0.0;
    // Device time of the certificate's brute force (cert_scan.comp; the band
    // itself is appended by the self-check, inside gpuSearch or gpuCull).
    double gpuCertificate = 0.0;
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
    // The band the backend left for the certificate (its queries and their
    // candidate targets), which the Engine settles in double from the
    // caller's coordinates; opaque, empty in a returned result.
    std::shared_ptr<const detail::ProofMaterial> proofMaterial;
    // The library's own out-of-core pieces only: a per-point call's queries
    // above its floor; opaque, empty in a returned result.
    std::shared_ptr<const detail::AboveFloor> aboveFloor;
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

class Engine;
// Device-resident input (rthdist/vulkan_interop.hpp: the only public header
// with Vulkan types): an Engine on the embedder's VkDevice reads point sets
// from its VkBuffers.
struct VulkanDevice;
struct DevicePointView;
// Point to surface (rthdist/surface.hpp: include it to call
// Engine::hausdorffToSurface).
struct MeshView;
struct SurfaceCallOptions;
struct SurfaceResult;

// A point set prepared once on an Engine's device (or, on the CPU backend,
// in host memory): its frame (origin), exact power-of-two scale, bounds, bit
// count and index, with a copy of its points (the self-check and the
// witnesses read them). Usable as query set and as target set of any number
// of later Engine::compute calls on the Engine that prepared it. Copies share
// one prepared set; the memory is released with the last copy (it keeps the
// Engine's device alive, so it may outlive the Engine). Not thread-safe: a
// prepared set is used by its Engine's calls, one at a time.
class RTHDIST_API PreparedSet {
public:
    PreparedSet(const PreparedSet&);
    PreparedSet& operator=(const PreparedSet&);
    PreparedSet(PreparedSet&&) noexcept;
    PreparedSet& operator=(PreparedSet&&) noexcept;
    ~PreparedSet();

    [[nodiscard]] size_t size() const;
    // Bit count of its index grid.
    [[nodiscard]] int bits() const;
    // The frame: subtracted before the float search (0 for float data).
    [[nodiscard]] glm::dvec3 origin() const;
    // Memory it holds now (device-local buffers; host copies and, on the CPU
    // backend, the index). Coarse search levels are added on first use.
    [[nodiscard]] uint64_t deviceBytes() const;
    [[nodiscard]] uint64_t hostBytes() const;

    struct Impl;

private:
    friend class Engine;
    explicit PreparedSet(std::shared_ptr<Impl> impl);
    std::shared_ptr<Impl> m_impl;
};

// One pair of a batch: indexes into the prepared sets given with it.
struct PairRef {
    size_t a = 0;
    size_t b = 0;
};

// Owns a Vulkan device, its pipelines and scratch memory between calls (or,
// on the CPU backend, nothing but its settings).
//
// Build once, query many: prepare() a set (a reference model, a scan of a
// time series) once and compute() it against any number of other prepared
// sets; each call then indexes nothing and uploads nothing. Two prepared sets
// meet in one frame (PrepareOptions::origin) and one exact scale; when they
// do not (double sets prepared with different origins, or magnitudes past
// 2^40 or below 2^-40 that need different scales) the call indexes both
// afresh in their union's frame, exactly as the one-shot call does.
class RTHDIST_API Engine {
public:
    [[nodiscard]] static Result<Engine> create(const EngineOptions& options);
    // As above; compute(a, b) without call options then uses the call part of `options`.
    [[nodiscard]] static Result<Engine> create(const Options& options);
    // On the embedder's Vulkan device, queue and instance (vulkan_interop.hpp:
    // borrowed, never destroyed; EngineOptions::backend kRayQuery,
    // kRtPipeline or kAuto; deviceIndex and devices are ignored). The only
    // Engines that take DevicePointViews.
    [[nodiscard]] static Result<Engine> create(const VulkanDevice& device, const EngineOptions& options);
    Engine(Engine&&) noexcept;
    Engine& operator=(Engine&&) noexcept;
    ~Engine();

    // One-shot: indexes both sets for this call only (on a GPU backend a
    // small pair with the automatic bit count is scanned whole instead, as
    // computeBatch describes; the result is the same H to float rounding).
    [[nodiscard]] Result<HausdorffResult> compute(PointView a, PointView b);
    [[nodiscard]] Result<HausdorffResult> compute(PointView a, PointView b, const CallOptions& call);

    // Checks and prepares one set (points as in compute: finite, non-empty,
    // at most 2^31 - 1: a prepared set is not split). The view is read during
    // this call only.
    [[nodiscard]] Result<PreparedSet> prepare(PointView points, const PrepareOptions& options = {});

    // Device input (vulkan_interop.hpp: synchronisation contract, buffer
    // usage, precision, limits): sets in the embedder's VkBuffers, read on
    // the device. The same results as the host-array calls on the same
    // coordinates. kInvalidArgument on an Engine not created on a VulkanDevice.
    [[nodiscard]] Result<HausdorffResult> compute(const DevicePointView& a, const DevicePointView& b);
    [[nodiscard]] Result<HausdorffResult> compute(const DevicePointView& a, const DevicePointView& b,
                                                  const CallOptions& call);
    [[nodiscard]] Result<PreparedSet> prepare(const DevicePointView& points,
                                              const PrepareOptions& options = {});
    // H(A, B) of two sets prepared by this Engine (either may be both).
    // Witness indices refer to each set's input order. Small pairs on a GPU
    // backend are scanned whole (computeBatch below).
    [[nodiscard]] Result<HausdorffResult> compute(const PreparedSet& a, const PreparedSet& b,
                                                  const CallOptions& call = {});
    // Many pairs in one call: result i is H(sets[pairs[i].a], sets[pairs[i].b])
    // (or its error; one failing pair does not stop the others, a cancelled
    // call fills the rest with kCancelled). On a GPU backend the small pairs
    // (sets of host arrays with one origin, each at most 2^22 points, queries
    // x targets at most 2^28 per direction, 2^20 on a CPU device such as
    // lavapipe) are scanned exactly, every query against every target with
    // the early break, in one submission per 2^24 queries; each reports an
    // equal share of its submission's time (Timings::total, refine,
    // gpuRefine) and counters without iterations. The other pairs run one
    // after another as compute() does.
    [[nodiscard]] std::vector<Result<HausdorffResult>> computeBatch(std::span<const PreparedSet> sets,
                                                                    std::span<const PairRef> pairs,
                                                                    const CallOptions& call = {});

    // h(points, surface) on this Engine's backend, which keeps its device,
    // pipelines and buffers between calls: the contract, precision, limits
    // and routes of hausdorffToSurface (rthdist/surface.hpp, "On a kept
    // device"), the same results (==). The views are read during the call
    // only. Like compute, one caller at a time.
    [[nodiscard]] Result<SurfaceResult> hausdorffToSurface(PointView points, MeshView surface);
    [[nodiscard]] Result<SurfaceResult> hausdorffToSurface(PointView points, MeshView surface,
                                                           const SurfaceCallOptions& call);

    // Hands back a result that is no longer needed: its per-point arrays
    // (aNearest, bNearest) become the next per-point call's on a GPU
    // backend, filled in place (no allocation, no zero-fill: ~1 ms per 5 x
    // 10^5 queries on a 16-core host). Optional; arrays of any size may be
    // given (the next call resizes them); the CPU backend drops them. Like
    // compute, one caller at a time.
    void recycle(HausdorffResult&& spent);
    // The same for a point-to-surface result: its per-point arrays
    // (SurfaceResult::perPoint) become the next per-point surface call's on
    // either backend, filled in place (pages already touched: at 10M points
    // 600 MB a call are not faulted in again). Optional, any size.
    void recycle(SurfaceResult&& spent);

    [[nodiscard]] const std::string& deviceName() const;
    [[nodiscard]] Backend backend() const;
    // The pipeline cache file (empty: none, e.g. the CPU backend) and
    // whether creation read it: "loaded", "none", or why it was ignored.
    [[nodiscard]] std::string pipelineCachePath() const;
    [[nodiscard]] std::string pipelineCacheStatus() const;

    struct Impl;

private:
    // The one-shot entry validates its inputs itself and calls the engine's
    // core directly, so the points are scanned once.
    friend RTHDIST_API Result<HausdorffResult> hausdorff(PointView a, PointView b, const Options& options);

    explicit Engine(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

// One-shot convenience: creates an Engine (or runs the CPU backend) and
// computes. The Engine's backend is oneShotBackendFor(a.count + b.count,
// options): with Backend::kAuto and no device named, a small pair runs on
// the CPU backend, which answers it before a GPU would be set up.
[[nodiscard]] RTHDIST_API Result<HausdorffResult> hausdorff(PointView a, PointView b,
                                                            const Options& options = {});

// The backend hausdorff() opens for a pair of `points` in all:
// options.backend, except Backend::kAuto with no device named (deviceIndex
// < 0, devices empty) and no validation, which takes the CPU backend for a pair of at most
// 2^18 points per host thread (options.threads; 0: every hardware thread;
// at most 32 counted):
// about 0.2 s of CPU time at most, where a GPU's device and pipelines take
// 0.2-0.75 s to set up (README "Backends"). Larger pairs, and every Engine
// (which keeps its device between calls), take the backend as chosen at
// creation. Pure: reads no device.
[[nodiscard]] RTHDIST_API Backend oneShotBackendFor(uint64_t points, const EngineOptions& options);

RTHDIST_API const char* versionString();

}  // namespace rthdist
