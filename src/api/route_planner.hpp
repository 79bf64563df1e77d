// The route of a call: one pure function from what the call is (its pair's
// shape, its options, the memory budget, what the backend can do) to how the
// Engine runs it. It reads no device and holds no backend object, so every
// route is unit-tested on the host (tests/api/route_planner_test.cpp);
// engine.cpp runs the route it returns through the backend interface
// (api/backend.hpp).
//
// The routes, in the order they are tried:
//   host views (Engine::compute(PointView, PointView), hausdorff()):
//     the pair within one call's budget:
//       kSmallPairScan  small enough to be scanned whole (GPU, automatic bits)
//       kDeviceIngest   packed float arrays the device checks and bounds itself
//       kOneCall        checked and framed on the host, one backend call
//                       (pieces after a kOutOfMemory under the automatic budget)
//     past it:
//       kSeveralDevices each device a share of the queries with all the targets
//       kPieces         out of core: query chunks x target tiles (out_of_core.hpp)
//   prepared sets (Engine::compute(PreparedSet, ...), computeBatch):
//       kRefused        another Engine's set, or a device view's set outside its frame
//       kSmallPairScan  one frame, small: scanned whole (a batch's in one submission)
//       kReframe        different frames or scales: the inputs as host views in the
//                       union's frame (the framed routes above, no device ingest)
//       kPrepared       the sets' own indexes
//   device views (Engine::compute(DevicePointView, ...)):
//       kRefused        a backend that reads no device views, or past the budget
//       kDeviceViews    ingested and searched on the device
//   a point set against a triangle surface (hausdorffToSurface, planSurfaceRoute),
//   and two surfaces (surfaceHausdorff, planSurfacePairRoute: the same routes, no refusal):
//       kRefused        per-point distances on a GPU backend (the CPU backend gives them)
//       kSurfaceCpu     the CPU backend's triangle BVH (api/surface.cpp); also kAuto,
//                       but for the calls autoSurfaceOnGpu sends to an Engine's kept device
//       kSurfaceGpu     a GPU backend named by the caller (or those calls): the device's float
//                       search over triangle boxes, proven in double on the host (api/surface_gpu.cpp)
// Host views that narrow (narrowingPays below, api/narrowed_targets.hpp) run
// as one call on both sets' cores or as two directed calls, each on the
// routes above.
// The pieces of kPieces and kSeveralDevices are planned as framed pairs
// (planFramedCall): a small piece is scanned whole.
#pragma once

#include <cstdint>
#include <string>

#include "api/out_of_core.hpp"
#include "core/scan_limits.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::api {

enum class Route {
    kRefused,
    kSmallPairScan,
    kDeviceIngest,
    kOneCall,
    kSeveralDevices,
    kPieces,
    kReframe,
    kPrepared,
    kDeviceViews,
    kSurfaceCpu,
    kSurfaceGpu,
};

[[nodiscard]] const char* routeName(Route route);

// What the call's pair is, as the planner needs it.
struct PairShape {
    enum class Input { kHostViews, kPreparedSets, kDeviceViews };
    Input input = Input::kHostViews;
    uint64_t a = 0, b = 0;  // points of each set
    // Host views: both packed float arrays (PointView::packedFloat).
    bool packedFloat = false;
    // Prepared sets:
    bool sameEngine = true;   // both prepared by this Engine
    bool onDevice = false;    // either prepared from a device view (no host copy)
    bool hostCopies = false;  // either keeps its double input (not float-exact)
    bool oneOrigin = false;   // one origin that keeps the contract's bound
    bool oneScale = false;    // and one exact scale (core::exactScale)
};

// What the Engine's backend can do (Backend::caps).
struct BackendCaps {
    core::ScanLimits scan;      // pairs scanned whole (maxWork 0: none)
    uint64_t ingestPoints = 0;  // device ingest of packed floats, both sets together (0: none)
    int lanes = 1;              // devices one-shot calls spread pieces over
    // A one-shot call that fit the budget but found the device short of
    // memory runs again in pieces (the automatic budget of a device).
    bool piecesOnOutOfMemory = false;
    // Why the backend reads no device views; empty when it does.
    std::string noDeviceViews;
    // A kDeviceIngest pair of at most kNarrowCheckPoints looks for narrowed
    // targets from boxes taken on the host before the ingest, not from the
    // ingest's own (Tuning::narrowHostBounds); larger pairs always from the
    // ingest's.
    bool narrowOnHost = false;
    // A narrowed pair's calls take the device ingest (Tuning::narrowedIngest;
    // engine.cpp computeNarrowedCall), else the host views whose boxes the
    // narrowing took.
    bool narrowedIngest = false;
    // A pair whose strays are their own (kilometres from the other set both
    // ways) runs on the two cores for h alone too (api::narrowPair's
    // `ownStrays`), not whole: the GPU backends' search of such a pair left
    // nearly every cluster query uncut in the stretched frame (2M double
    // points in a 5 cm cube beside one km stray per set: 2.8 s of refinement
    // on an H200; 100k on lavapipe 1.58 s, 99,967 of 100,001 queries
    // surviving the cull), where the CPU backend's whole search settles them
    // at once (0.13 s, 391 surviving). Per-point calls take the cores on
    // every backend.
    bool coresForOwnStrays = false;
};

struct Plan {
    Route route = Route::kRefused;
    // kRefused: the error the call returns.
    ErrorCode code = ErrorCode::kInvalidArgument;
    std::string reason;
    // kOneCall, kSmallPairScan: pieces after a kOutOfMemory (BackendCaps).
    bool piecesOnOutOfMemory = false;
    // The budget pieces are cut to: kSeveralDevices and kPieces, and
    // kOneCall and kSmallPairScan after a kOutOfMemory.
    MemoryBudget pieces;
};

// The route of a call.
[[nodiscard]] Plan planRoute(const PairShape& shape, const CallOptions& call, const MemoryBudget& budget,
                             const BackendCaps& caps);

// The route of a point set against a triangle surface, chosen before any
// backend is opened (one-shot: `requested` is SurfaceOptions::backend; on an
// Engine: its EngineOptions::backend, whose device is kept): Backend::kCpu
// takes kSurfaceCpu; a GPU backend the caller named takes kSurfaceGpu,
// per-point distances too (within the float search's tolerance,
// rthdist/surface.hpp). Backend::kAuto takes kSurfaceCpu one-shot (a GPU
// call opens a device per call, whose setup, 0.36-0.74 s on the H200
// hosts, outweighs the CPU search at the sizes one call takes) and, on an
// Engine that keeps a GPU device, kSurfaceGpu where autoSurfaceOnGpu says
// so (below).
struct SurfaceShape {
    uint64_t queries = 0;     // points of the call
    uint64_t triangles = 0;   // of the surface
    bool perPoint = false;    // SurfaceCallOptions::perPointDistances (also the evaluation's)
    bool keptDevice = false;  // an Engine whose backend is a GPU's (not one-shot, not the CPU backend)
};
[[nodiscard]] Plan planSurfaceRoute(Backend requested, const SurfaceShape& shape = {});

// An auto Engine with a kept GPU device sends a point-to-surface call to it
// when the call asks the directed value only (the device's per-point
// entries are within a tolerance, the CPU backend's exact: auto keeps one
// contract) and has at least kAutoSurfaceGpuQueries queries and at least as
// many queries as triangles. The GPU route builds a BLAS of every triangle
// each call and pays ~0.5 ms of fixed cost; the CPU backend's kept tree is
// searched in O(log F) a query. Measured on one H200 with 16 host threads,
// kept Engines (docs/bench/surfaces, sessions 11, 22, 23), every row where
// queries >= triangles was faster on the GPU (bunny>res2-res4 1.3-1.8x,
// armadillo>dec 1.4x, scans>bunny 3.2x, dragon>res2 3.3x, 1M-10M samples
// to dragon res3 9-11x) and every row with fewer was not (bunny-res4>bunny
// 453 queries to 69k triangles 0.8 vs 1.7 ms, dragon-res4>dragon 1.2 vs 17,
// armadillo-dec>armadillo 1.1 vs 1.8, bunny>t0.1 3.1 vs 7.7; bunny>t0.001,
// 36k to 69k, the one near miss: 2.7 vs 2.3). With fewer host threads the
// CPU side is slower, so the rule errs toward the CPU there.
inline constexpr uint64_t kAutoSurfaceGpuQueries = uint64_t(1) << 14;
[[nodiscard]] bool autoSurfaceOnGpu(const SurfaceShape& shape);

// The route of two triangle surfaces (surfaceHausdorff, certified bounds):
// kSurfaceCpu for kCpu and kAuto (the refinement's batches run on the CPU
// backend's BVH); kSurfaceGpu for a GPU backend the caller named (the
// batches on the device's search, each batch's maximum proven on the host:
// api/surface_pair_gpu.hpp), never computed on the CPU in its place.
[[nodiscard]] Plan planSurfacePairRoute(Backend requested);

// Narrowed targets (api/narrowed_targets.hpp), host views: a direction
// whose targets can be narrowed to those within reach of its queries' box
// is searched alone, its targets narrowed, in its own frame, when that
// frame's magnitude (and with it the float search's rounding slack) is at
// most 2^-kNarrowGainLog2 of the whole pair's; the other direction as it is.
// Never where the narrowed frame's magnitude is nonzero and below 2^-126
// (core::kMinShifted: float32's normals; a frame that small cannot be
// searched, while the whole pair's can: a double point 1e-40 from its
// nearest beside a stray 1 km away stays one pair).
inline constexpr int kNarrowGainLog2 = 8;
[[nodiscard]] bool narrowingPays(double wholeMagnitude, double narrowedMagnitude);
// A kDeviceIngest pair of at most this many points in all may look for
// narrowed targets from boxes taken on the host (one pass per set) before
// the ingest (BackendCaps::narrowOnHost); larger ones, and every pair where
// the backend leaves it to the ingest, look from the ingest's own bounds
// (no pass of their own: a pair that does not narrow pays a 256-point
// sample a set). Until session 17 larger pairs did not look at all: the
// 5M-point cluster with a common far point took 8.2-8.7 s on an H200
// (every query to the rays) against CuPy's KDTree's 0.33 s.
inline constexpr uint64_t kNarrowCheckPoints = uint64_t(1) << 22;

// The backend of a one-shot call (hausdorff(), the CLI) of `points` in
// all: Backend::kAuto with no device named (EngineOptions::deviceIndex < 0,
// no EngineOptions::devices) and no validation layer asked for
// (`vulkanAsked` false) takes the CPU backend for a pair of at most
// kOneShotCpuPointsPerThread points per host thread (`threads`: the
// resolved count), whose exact answer it has in about 0.2 s of CPU time at
// most (the crowded sphere, the densest of the scale suite: ~1.4M points a
// thread-second on a 16-core H200 host; the Dragon rows and surface
// samplings 3-7M), where a GPU's one-shot call first opens a device and
// makes its pipelines: 0.36-0.45 s on a 16-core H200 host, 0.63-0.74 s on
// a 32-core one (the driver's VkDevice alone 0.4-0.55 s; session 21). There
// the CLI's wall on surface-1M (2M points) went 445-510 -> 45-53 ms and on
// the Dragon pairs 442-527 -> 203-301 ms (their gzip'd load now most of
// it). Every other request, and larger pairs, as asked: an Engine keeps its
// device between calls, and its backend is never chosen by size.
inline constexpr uint64_t kOneShotCpuPointsPerThread = uint64_t(1) << 18;
// Threads counted at most (the CPU backend's rate was measured up to 32: the
// crowded sphere's 40M points in 0.8 s on a 32-core host; past that its
// scaling is not known): at most 8.4M points go to the CPU this way.
inline constexpr int kOneShotCpuThreads = 32;
[[nodiscard]] Backend oneShotBackend(Backend requested, bool vulkanAsked, uint64_t points, int threads);

// The route of a pair already checked and framed on the host (float sets of
// one frame and scale): kSmallPairScan, kOneCall, kSeveralDevices or kPieces.
// kReframe's pair and every piece of kPieces take it.
[[nodiscard]] Plan planFramedCall(uint64_t a, uint64_t b, const CallOptions& call, const MemoryBudget& budget,
                                  const BackendCaps& caps);

}  // namespace rthdist::api
