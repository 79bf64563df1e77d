// The point-to-surface search on the device (issue 34; design.md §11): the
// RT-HDIST scheme of the point search (candidate_search.hpp) with triangles
// for targets, then a tree descent for the queries it leaves open.
//   The radii: one procedural AABB per triangle in a BLAS, its box grown by
// a radius R (refitted for the second radius); one ray of tiny length per
// query not yet settled (ray query, or the ray-tracing pipeline of
// surface_search.rgen/rint), and every triangle whose grown box the ray
// starts in is measured by the shared rule
// (shaders/shared/rthdist_point_triangle.h) in float, the query keeping
// its nearest. A query whose nearest lies within R is settled (a nearer
// triangle's box lies within R too, so it was visited: up to float
// rounding). One submission holds the radii of SurfaceRadii::start, which
// settle nearly every query of inputs near each other.
//   The tail: a query farther than the last radius (inputs apart, far
// outliers) would need larger radii, where each ray sits in thousands of
// overlapping grown boxes. Instead, when many queries are open, the host
// builds the float BVH of the triangles (surface_tree.hpp) and one more
// submission runs surface_tail.comp: every open query descends it
// nearest-first from the best the rays found, by the same per-triangle
// test, so it ends with what a visit of every triangle would give. The
// tree (with its own copy of the corners, in its order) stays on the
// device for the next call, which descends it without a build while the
// triangles' float corners are the same (bit for bit against a host copy,
// compared only where the tree is wanted). A few open queries
// (open x triangles at most the host work, surfaceHostWork) are handed
// back instead (SurfaceCandidates::open): the caller's proof measures them
// exactly on the host, which costs less than the tree's build and a second
// submission.
//
// The answer is a candidate, not a value: each query's nearest triangle
// (or none). The caller proves the directed maximum in double on the host
// (api/surface_certify.hpp), so a rounding or a miss here costs host work,
// never a wrong value; the radii and the tree decide cost only.
//
// Kept between calls (one per GpuHausdorff): its buffers only grow, and the
// BLAS storage is the workspace's (a later point search rebuilds it).
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "core/framed_queries.hpp"
#include "core/searched_tops.hpp"
#include "core/uninit_vector.hpp"
#include "gpu/buffer.hpp"
#include "rthdist/tuning.hpp"
#include "rthdist_surface_search.h"

namespace rthdist::gpu_algo {

namespace sh = rthdist::shared;
struct Workspace;

struct SurfaceCandidates {
    core::UninitVector<uint32_t> triangle;  // per query: its nearest triangle found, UINT32_MAX for none
    // Per query: the squared distance the device measured to `triangle`
    // (the shared rule in float, in the search frame), +inf for none.
    core::UninitVector<float> distance2;
    core::SearchedTops tops;   // distance2's largest by chunks, from the read-back's pass
    uint32_t radii = 0;        // radii that searched a query
    uint64_t rays = 0;         // rays cast over all radii
    uint32_t submissions = 0;  // command buffers submitted (each waited for)
    double firstRadius = 0.0;  // in the search frame (|coordinate| <= 1)
    double gpuMs = 0.0;        // device time of the submissions
    double gpuBuildMs = 0.0;   // of which the triangles' boxes and BLAS builds and refits
    double stageMs = 0.0;      // host: the inputs written to the upload buffer, the radii's statistics
    double submitMs = 0.0;     // host wall: recording, submitting and waiting for the submissions
    double readbackMs = 0.0;   // host: the candidates taken from the read-back buffer
    // The queries the radii left open, where they were few (open x
    // triangles at most Tuning::surfaceHostWork): no tail ran; their
    // `triangle` is the rays' best (or none), and the caller measures them
    // exactly. In index order.
    std::vector<uint32_t> open;
    // The tail (0 where it did not run):
    uint64_t tailQueries = 0;     // queries that descended the tree on the device
    bool tailTreeReused = false;  // the tree of the call before (the same corners): not built
    uint32_t tailLanes = 0;       // threads a query of the descent (tailLaneBits)
    double tailBuildMs = 0.0;     // host: the tree built and written to the upload buffer (part of submitMs)
    double tailGpuMs = 0.0;       // device time of the tail's submission (part of gpuMs)
};

// Where the queries the radii leave open go (host only; tests/gpu_algo/
// surface_radii_test.cpp): back to the host, whose proof measures them
// exactly (SurfaceCandidates::open), while open queries x triangles is at
// most the host work, else down the tail's tree on the device. Measured on
// 2 cores (docs/bench/surfaces, session 7): the host's brute force costs
// ~3 ns per query and triangle on one thread (a box test each: one pass
// over the triangles for all of them, on the worker pool); the tree's build
// ~30 ns per triangle (2 ms for the bunny's 69,451 triangles on one thread,
// little of it parallel at that size), then a second submission; on the
// H200 the tail added ~4.8 ms of host time with 8 open queries (session
// 6). So the host takes ~2^19 pairs per host thread (~1.6 ms): 15 open
// queries of the bunny on 2 threads, 120 on 16.
inline constexpr uint64_t kSurfaceHostWorkPerThread = uint64_t(1) << 19;
// Tuning::surfaceHostWork, else kSurfaceHostWorkPerThread x the host's
// threads (threads: EngineOptions::threads, 0: every hardware thread).
[[nodiscard]] uint64_t surfaceHostWork(const Tuning& tuning, int threads);
// True when `open` queries of `triangles` go to the host under `hostWork`.
[[nodiscard]] bool openQueriesToHost(uint64_t open, uint64_t triangles, uint64_t hostWork);

// Where a call skips the radii and every query descends the tail's tree
// from none (host only; tests/gpu_algo/surface_radii_test.cpp): at most
// kDescendQueries queries, whatever the triangles. Since the tree splits
// at the Morton codes' highest differing bit (surface_tree.hpp), the
// descent beat the radii on every row measured, on the H200 (session 30,
// kept rt-pipeline, medians of 3 processes): bunny-scans>bunny's 362,272
// queries 2.78 -> 1.23 ms, dragon>dragon-res2's 437,645 3.34 -> 1.40,
// 4,000,000 samples of dragon_vrip_res2 against its 202,520 triangles
// 13.58 -> 10.65; within 2^17 as before (bunny>bunny moved by 0.1 of the
// diagonal 2.83 -> 1.76, dragon-res2>dragon 6.37 -> 1.17). Past 2^22
// queries, not measured, the radii stay (the descent's lead narrowed from
// 2.3x to 1.3x by 4M queries). The descent ends with what a visit of every
// triangle would give, as after the radii.
inline constexpr uint64_t kDescendQueries = uint64_t(1) << 22;
// Tuning::surfaceDescend decides where it is set.
[[nodiscard]] bool descendOnly(const Tuning& tuning, uint64_t queries);

// The threads a query of the tail's descent (surface_tail.comp), as the log2
// of their count (host only; tests/gpu_algo/surface_radii_test.cpp). One
// thread a query keeps the device busy where many queries descend; a few
// leave a GPU nearly idle, each descent a chain of dependent reads, so
// lanes share each query's tree until about kTailThreads threads descend
// (at most 2^kTailMostLaneBits a query; an H200 holds ~2^18 threads at
// once: at 2^16, session 27, 5,205 queries took 8 lanes and 0.53 ms of
// GPU time, 32 lanes 0.30 ms). A CPU device (lavapipe) takes one lane: its
// threads are its cores', and lanes only add work there. `descending`: the
// queries that descend (every query, or those the radii left open);
// `queries`: the call's, a dispatch's threads being queries x lanes (at
// most kTailMostThreads, and below 2^32). Tuning::surfaceTailLanes decides
// where it is set, on any device (rounded down to a power of two, within
// the same limits).
inline constexpr uint64_t kTailThreads = uint64_t(1) << 18;
inline constexpr uint64_t kTailMostThreads = uint64_t(1) << 24;
inline constexpr uint32_t kTailMostLaneBits = 5;
[[nodiscard]] uint32_t tailLaneBits(const Tuning& tuning, bool cpuDevice, uint64_t descending,
                                    uint64_t queries);

// The radii of one search (host only; tests/gpu_algo/surface_radii_test.cpp).
// None decides a value (the host proves it); they set how many queries the
// radii settle and how many the tail's tree descent is left with.
//   first: the larger of half the mean longest side of the triangles' boxes
//     (a query on or near the surface settles at once) and half the mean
//     spacing of the queries over the surface, sqrt(area / queries): at that
//     radius a query meets about 0.8 F / Q triangles, so the first radius
//     measures O(F + Q) triangles however few the queries are, and a sparse
//     query set (a coarse mesh's vertices against a fine one) settles in one
//     pass instead of a refit of every triangle per doubling.
//   cover: the diagonal of the union of both inputs' boxes (grown for
//     rounding), where every grown box holds every query.
class SurfaceRadii {
public:
    // meanSide: of the triangles' boxes' longest sides; area: of the
    // triangles; diagonal: of the union's box; all in the search frame.
    SurfaceRadii(double meanSide, double area, uint64_t queries, double diagonal);
    [[nodiscard]] double first() const { return m_first; }
    // The one submission's radii: first and 4x it (at most cover). The
    // first radius leaves few queries open on inputs near each other (1 of
    // 35,947 on bunny>res2, 1 of 5,205 on dragon-res4>dragon, 576 of
    // 437,645 on dragon>res2 on lavapipe, docs/bench/surfaces), and the
    // second settles most of those; the tail takes the rest.
    [[nodiscard]] std::vector<double> start() const;
    [[nodiscard]] double cover() const { return m_cover; }
    static constexpr size_t kStartRadii = 2;  // at most, in start()

private:
    double m_first = 0.0, m_cover = 0.0;
};

class SurfaceSearch {
public:
    explicit SurfaceSearch(Workspace& ws) : m_ws(ws) {}

    // queries: the points in the search frame; corners: a, b, c of every
    // triangle in the same frame (3 per triangle). Fewer than 2^30
    // triangles and 2^32 queries; a BLAS past the device's
    // maxPrimitiveCount throws gpu::LimitError. One submission of the
    // radii, then one of the tail where a query is open; where descendOnly,
    // one submission of the upload and the tail for every query. `cancel` is read
    // after each (true: throws CallCancelled). Vulkan failures throw.
    // cornersVersion: 0, or the caller's name for these very corners (a
    // value it never gives other corners): a tree kept from a call of the
    // same version is used without comparing the corners again.
    [[nodiscard]] SurfaceCandidates run(const core::FramedQueries& queries,
                                        std::span<const glm::vec3> corners,
                                        const std::atomic<bool>* cancel = nullptr,
                                        uint64_t cornersVersion = 0);
    // Frees the buffers kept between calls (GpuHausdorff::releaseScratch).
    void release();

private:
    struct Stats;
    // The queries, and for the radii (`rays`) the corners and the
    // triangles' tight boxes (search cells of one triangle each), written
    // to the upload buffer on the worker pool, with the statistics of the
    // radii; the device buffers grown. `extra`: bytes of the upload buffer
    // kept after the inputs (the tail's tree, where descendOnly: the
    // descent reads the tree's own copy of the corners, so no corners or
    // boxes go up); the inputs' bytes are inputBytes(rays).
    Stats stage(const core::FramedQueries& queries, std::span<const glm::vec3> corners, bool rays,
                VkDeviceSize extra = 0);
    [[nodiscard]] VkDeviceSize inputBytes(bool rays) const;
    // The upload buffer's copies (the corners and boxes for the radii) and
    // every query's best set to none.
    void cmdUpload(VkCommandBuffer cmd, bool rays);
    // One submission: its radii (each: grown boxes, BLAS build or refit,
    // rays), then every query's best copied for the host. Returns what each
    // radius did.
    std::vector<sh::SurfaceRadiusCount> submitRadii(VkCommandBuffer cmd, std::span<const double> radii,
                                                    SurfaceCandidates& out);
    // One radius: the boxes grown, the BLAS built or refit, the rays. Returns
    // the timestamp mark after the builds (the stage split of gpuBuildMs).
    uint32_t cmdRadius(VkCommandBuffer cmd, double radius, double settled2, bool update,
                       VkDeviceAddress counts);
    // The tail's tree for this call's corners: the one kept from the call
    // before where the corners are the same (of the same nonzero version,
    // else every float bit for bit against the kept copy m_treeCorners),
    // else built on the host (its device buffers grown).
    struct TailTree;
    TailTree tailTree(std::span<const glm::vec3> corners, SurfaceCandidates& out);
    // A built tree, its nodes and its copy of the corners in its order,
    // written to the upload buffer at byte `at` (grown when `at` is 0; else
    // stage() kept the room).
    void stageTail(const TailTree& tree, std::span<const glm::vec3> corners, VkDeviceSize at);
    // The tree's copies from the upload buffer (a built one) and the
    // descent of every query whose best is farther than `settled`
    // (`descending` of them: tailLaneBits; out.tailLanes set).
    void cmdTail(VkCommandBuffer cmd, const TailTree& tree, VkDeviceSize at, double settled,
                 uint64_t descending, SurfaceCandidates& out);
    // After the tail's submission: the tree kept (with a copy of the
    // corners it holds), the tail's counts.
    void finishTail(const TailTree& tree, std::span<const glm::vec3> corners, SurfaceCandidates& out);
    // The tail's submission for the queries the radii left open (their best
    // farther than `settled`): tailTree, the descent, every query's best
    // copied for the host.
    void submitTail(std::span<const glm::vec3> corners, double settled, uint64_t open,
                    SurfaceCandidates& out);
    // Every query's best copied to the read-back buffer for the host.
    void cmdReadBack(VkCommandBuffer cmd);

    Workspace& m_ws;
    uint32_t m_queries = 0, m_triangles = 0;
    double m_rayTMax = 0.0;
    bool m_built = false;  // the BLAS of this call is built (the next radius refits it)
    gpu::Buffer m_points, m_corners, m_boxes, m_best, m_aabbs, m_staging, m_readback, m_counts;
    // The tail's tree (surface_tree.hpp): its nodes, and the corners of the
    // triangle at each of its sorted positions (SurfaceTailPush::leafCorners).
    gpu::Buffer m_nodes, m_leafCorners;
    // Of which corners m_nodes and m_leafCorners hold the tree (empty:
    // none): a kept tree is used only for these very corners, so the
    // device's distances are those of the call's own triangles, which the
    // host's proof relies on (api/surface_certify.hpp, searched2).
    std::vector<glm::vec3> m_treeCorners;
    uint64_t m_treeVersion = 0;  // their caller's version (0: none given)
    uint64_t m_version = 0;      // this call's (run's cornersVersion)
};

}  // namespace rthdist::gpu_algo
