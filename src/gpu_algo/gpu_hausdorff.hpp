// The GPU form of RT-HDIST (Kim, Lee, Kim 2025) on Vulkan, with the exactness
// fixes of design.md §3-4:
//   1. index space (compute): cell keys, counting sort over a dense key table,
//      run-length encode into occupied cells with tight boxes;
//   2. neighbourhood pass (compute): exact NN inside the 3x3x3 cell block,
//      early break against the running maximum -> most queries die here;
//   3. candidate search (ray query or rt pipeline): boxes grown by radius R,
//      every reported cell within R (and beyond the scanned radius rLo)
//      becomes a (query, cell) pair unless its representative kills the query;
//   4. refinement (compute): exact scan of the pairs' cells, early break;
//      resolve: best <= R -> exact NN; best < threshold -> dead; else R grows.
// A set's index (step 1) depends on that set alone, so a prepared set
// (prepare) is indexed once and searched by any number of calls.
//
// Threading: one caller at a time per GpuHausdorff (it owns the scratch
// buffers and the acceleration structures of its device).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/framed_queries.hpp"
#include "core/input_frame.hpp"
#include "core/per_point_floor.hpp"
#include "core/scan_limits.hpp"
#include "gpu_algo/set_points.hpp"
#include "gpu_algo/surface_search.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu {
class Context;
}

namespace rthdist::gpu_algo {

// A set indexed on the device, with the buffers it owns.
struct DeviceSet;

class GpuHausdorff {
public:
    // cacheDir: where the pipeline cache file lives (gpu/pipeline_cache.hpp);
    // empty: none.
    // threads: the host's passes over the points (EngineOptions::threads;
    // 0: every hardware thread).
    [[nodiscard]] static Result<std::unique_ptr<GpuHausdorff>> create(gpu::Context& ctx,
                                                                      const std::string& cacheDir,
                                                                      int threads, const Tuning& tuning);
    ~GpuHausdorff();

    // One-shot: both sets indexed for this call, in buffers pooled between
    // calls. `scale`: the exact power of two of index_space.hpp for both sets
    // (core::exactScale of their largest magnitude). The Engine's planner
    // (api/route_planner.hpp) picks scanWhole or computeIndexed itself;
    // compute picks by scansWhole.
    [[nodiscard]] Result<HausdorffResult> compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                  double scale, const CallOptions& options);
    // `floor` (per-point calls with perPointNearestOnly; ignored otherwise):
    // queries below it may stop there (core/per_point_floor.hpp).
    [[nodiscard]] Result<HausdorffResult> computeIndexed(std::span<const glm::vec3> a,
                                                         std::span<const glm::vec3> b, double scale,
                                                         const CallOptions& options,
                                                         const core::PerPointFloor& floor = {});
    // A small pair (scanLimits) staged by the host and scanned whole in one
    // submission (small_pairs.hpp).
    [[nodiscard]] Result<HausdorffResult> scanWhole(std::span<const glm::vec3> a,
                                                    std::span<const glm::vec3> b, double scale,
                                                    const CallOptions& options);
    // One-shot from packed float host arrays through the device ingest path
    // (ingest.comp): the host copies each array once into memory the device
    // reads; validation (NaN/Inf: kInvalidArgument naming the set and the
    // point), bounds and the bit count's sample come from the device. The
    // caller has checked only the views' shape (count, pointer). For sets
    // that ingests() accepts.
    // `leave`, when given, sees both sets' bounds once the device has them
    // (before any index is built); true ends the call there, with an empty
    // result (the caller takes another route: api/narrowed_targets.hpp).
    [[nodiscard]] Result<HausdorffResult> computePacked(
        std::span<const glm::vec3> a, std::span<const glm::vec3> b, const CallOptions& options,
        const std::function<bool(const core::Bounds&, const core::Bounds&)>& leave = {});
    // The points (both sets together) computePacked takes: both indexed in
    // one submission, each with scratch of its own (2^25).
    [[nodiscard]] static uint64_t ingestPoints();
    // As above, the scale taken from the points (one pass over each).
    [[nodiscard]] Result<HausdorffResult> compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                  const CallOptions& options);

    // Indexes one set into buffers of its own. `points` (float, before the
    // exact power-of-two `scale` of index_space.hpp) must outlive the set;
    // `name` labels its buffers and the self-check's messages. Index and
    // upload times are added to `timings`.
    [[nodiscard]] Result<std::shared_ptr<DeviceSet>> prepare(std::span<const glm::vec3> points, double scale,
                                                             int bits, const std::string& name,
                                                             Timings& timings);
    // H (or h) of two prepared sets of the same scale. Their coarse search
    // levels are built on first use and kept.
    [[nodiscard]] Result<HausdorffResult> compute(DeviceSet& a, DeviceSet& b, const CallOptions& options);

    // computeBatch's small pairs (small_pairs.hpp): which pairs are small
    // enough to be scanned whole (the planner's rule for prepared sets of
    // host arrays, one-shot pairs and pieces), and every such pair of a
    // batch in one submission, witnesses and per-point distances
    // recomputed in double from the sets' inputs (as compute(DeviceSet&, ...)
    // returns them). The sets must share an origin; their scales may differ
    // (both brought to the smaller, exactly). A device error fails every
    // pair; a pair that breaks the self-check fails alone (kInternal).
    [[nodiscard]] const core::ScanLimits& scanLimits() const;
    // Whether compute(a, b, scale, options) scans one-shot sets of these
    // sizes whole (with the automatic bit count only: a call that sets bits
    // asks for the index).
    [[nodiscard]] bool scansWhole(size_t aPoints, size_t bPoints, const CallOptions& options) const;
    [[nodiscard]] std::vector<Result<HausdorffResult>> computeSmallPairs(
        std::span<const std::pair<const DeviceSet*, const DeviceSet*>> pairs, const CallOptions& options);

    // Device input (rthdist/vulkan_interop.hpp; device_input.hpp): one-shot H
    // of two views of the embedder's buffers, ingested on the device; the
    // result's origin is the frame chosen (core::searchOrigin of the boxes
    // the device reduced). The caller checked the views against the
    // contract's limits and the memory budget.
    [[nodiscard]] Result<HausdorffResult> computeDevice(const DeviceInput& a, const DeviceInput& b,
                                                        const CallOptions& options);
    // A set prepared from a view: as prepare, with its frame (`origin` as
    // PrepareOptions::origin) and summary returned. It keeps a device copy of
    // the view's bytes (its witnesses are read there, never in the
    // embedder's buffer after this call).
    struct PreparedDevice {
        std::shared_ptr<DeviceSet> set;
        core::SetSummary summary;
        glm::dvec3 origin{0.0};
    };
    [[nodiscard]] Result<PreparedDevice> prepareDevice(const DeviceInput& view,
                                                       const std::optional<glm::dvec3>& origin, int bits,
                                                       const std::string& name, Timings& timings);
    [[nodiscard]] static uint64_t deviceBytes(const DeviceSet& set);
    [[nodiscard]] static int bits(const DeviceSet& set);

    [[nodiscard]] const std::string& pipelineCachePath() const;
    // "loaded", "none", or why the file was ignored.
    [[nodiscard]] const std::string& pipelineCacheStatus() const;

    // Caps the candidate-pair buffer (default 2^26 pairs); tests shrink it
    // so that queries must retry until their pairs fit.
    void setMaxPairCapacity(uint64_t pairs);
    // Caps the list of a floor call's queries above its floor (default
    // kAboveFloorCapacity); tests shrink it so that the dense read-back
    // takes over.
    void setAboveFloorCapacity(uint32_t queries);
    // Box tests (leaf groups and leaves) the neighbourhood pass makes in one
    // crowded cell at most (default kCullCellTests); past them the cell is
    // left to the search. Tests set 0 (a crowded cell gives its first point
    // only) so that crowded queries reach the search, or a few so that some
    // cells are scanned whole and others not.
    void setCullCellTests(uint32_t tests);
    // Leaves per leaf group of the split indexes built from now on (default
    // kLeafGroupLeaves, at least 1); tests use small groups so that cells
    // hold many.
    void setLeafGroupLeaves(uint32_t leaves);
    // A host-staged set of more than `past` points goes up through a host
    // buffer of `chunk` points, in halves (defaults kChunkedUploadPoints,
    // kUploadChunkPoints);
    // tests shrink both to run the chunked path at small sizes.
    void setUploadChunks(size_t past, size_t chunk);
    // A set of at least `points` whose points lie in space order has its
    // index built spread over each warp (space_order.hpp; default
    // kMinSpaceOrderPoints); tests lower it to run that path at small sizes.
    void setSpaceOrderMinPoints(size_t points);
    // Requests of at least `bytes` may adopt a spent buffer of the call
    // (Workspace::spare; default kAdoptMinBytes); tests set 0 so that small
    // inputs adopt too.
    void setAdoptMinBytes(uint64_t bytes);
    // How many spent buffers requests have adopted so far (tests).
    [[nodiscard]] uint64_t adoptedBuffers() const;
    // How many spent buffers wait in the workspace for a request (tests).
    [[nodiscard]] size_t spareBuffers() const;
    // Frees the scratch buffers and acceleration structures kept between
    // one-shot calls (the next call allocates them again). Out-of-core calls
    // free one direction's before the other's. Prepared sets keep theirs.
    void releaseScratch();
    // Bit k set: the last call (compute of any kind, also one that failed)
    // called CallOptions::perPointReady for direction k itself — early, from
    // runPair, while the other direction was searched. 0 after
    // releaseScratch. The API calls it for the directions left, at the end.
    [[nodiscard]] uint32_t handedBack() const;
    // Takes back the per-point arrays of an earlier result (out-of-core tile
    // calls, one after another): the next per-point call fills them in place
    // of fresh ones, whose zero-fill on one thread and first-touch page
    // faults cost about as much as the read-back itself (10^8 queries);
    // `b` serves the next h(B,A) (Engine::recycle).
    void recyclePerPoint(PerPoint&& a, PerPoint&& b = PerPoint{});

    // The point-to-surface search (surface_search.hpp): every query's
    // nearest triangle as the device found it, a candidate the caller proves
    // in double (a few open queries handed back for the caller to measure:
    // SurfaceCandidates::open). queries and corners (3 per triangle) in one
    // float frame; `cancel` read between submissions (kCancelled). Its
    // buffers, the tail's tree and the BLAS storage stay for the next call
    // (releaseScratch frees them). cornersVersion: SurfaceSearch::run's.
    [[nodiscard]] Result<SurfaceCandidates> nearestTriangles(const core::FramedQueries& queries,
                                                             std::span<const glm::vec3> corners,
                                                             const std::atomic<bool>* cancel = nullptr,
                                                             uint64_t cornersVersion = 0);
    [[nodiscard]] Result<SurfaceCandidates> nearestTriangles(std::span<const glm::vec3> queries,
                                                             std::span<const glm::vec3> corners) {
        return nearestTriangles(core::FramedQueries::of(queries), corners);
    }

    struct State;

private:
    explicit GpuHausdorff(std::unique_ptr<State> state);
    std::unique_ptr<State> m_state;
};

}  // namespace rthdist::gpu_algo
