// The point-to-surface search on the device (issue 34; design.md §11): the
// RT-HDIST scheme of the point search (candidate_search.hpp) with triangles
// for targets. One procedural AABB per triangle in a BLAS, its box grown by
// a radius R (refitted as R grows); one ray of tiny length per query not
// yet settled (ray query, or the ray-tracing pipeline of
// surface_search.rgen/rint), and every triangle whose grown box the ray
// starts in is measured by the shared rule
// (shaders/shared/rthdist_point_triangle.h) in float, the query keeping
// its nearest. A query whose nearest lies within R is settled (a nearer
// triangle's box lies within R too, so it was visited: up to float
// rounding); the others go on with a larger R, up to a radius that covers
// the union of both inputs' boxes, where every query meets every triangle.
//
// The answer is a candidate, not a value: each query's nearest triangle
// (or none). The caller proves the directed maximum in double on the host
// (api/surface_certify.hpp), so a rounding or a miss here costs host work,
// never a wrong value; the radii (SurfaceRadii) decide cost only.
//
// Kept between calls (one per GpuHausdorff): its buffers only grow, and the
// BLAS storage is the workspace's (a later point search rebuilds it).
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.hpp"
#include "rthdist_surface_search.h"

namespace rthdist::gpu_algo {

namespace sh = rthdist::shared;
struct Workspace;

struct SurfaceCandidates {
    std::vector<uint32_t> triangle;  // per query: its nearest triangle found, UINT32_MAX for none
    uint32_t radii = 0;              // radii that searched a query
    uint64_t rays = 0;               // rays cast over all radii
    uint32_t submissions = 0;        // command buffers submitted (each waited for)
    double firstRadius = 0.0;        // in the search frame (|coordinate| <= 1)
    double gpuMs = 0.0;              // device time of the submissions
    double gpuBuildMs = 0.0;         // of which the triangles' boxes and BLAS builds and refits
    double stageMs = 0.0;            // host: the inputs written to the upload buffer, the radii's statistics
    double submitMs = 0.0;           // host wall: recording, submitting and waiting for the submissions
    double readbackMs = 0.0;         // host: the candidates taken from the read-back buffer
};

// The radii of one search (host only; tests/gpu_algo/surface_radii_test.cpp).
// None decides a value (the host proves it); they set how many queries the
// first pass settles and how many BLAS refits the rest costs.
//   first: the larger of half the mean longest side of the triangles' boxes
//     (a query on or near the surface settles at once) and half the mean
//     spacing of the queries over the surface, sqrt(area / queries): at that
//     radius a query meets about 0.8 F / Q triangles, so the first pass
//     measures O(F + Q) triangles however few the queries are, and a sparse
//     query set (a coarse mesh's vertices against a fine one) settles in one
//     pass instead of a refit of every triangle per doubling.
//   next: after a submission, the radius doubles while its last radius
//     settled a fair share of what it searched and many queries are open;
//     it grows 4x when at most 1/16 of the queries are open (few rays: the
//     BLAS refits are the cost) or when the last radius settled at most
//     1/16 of its queries (far below their distances: inputs far apart).
//     The last radius is `cover`, the diagonal of the union of both
//     inputs' boxes (grown for rounding), where every grown box holds every
//     query.
class SurfaceRadii {
public:
    // meanSide: of the triangles' boxes' longest sides; area: of the
    // triangles; diagonal: of the union's box; all in the search frame.
    SurfaceRadii(double meanSide, double area, uint64_t queries, double diagonal);
    [[nodiscard]] double first() const { return m_first; }
    // The first submission's radii: first and 4x it (at most cover), as
    // next() grows a tail: the first radius leaves few queries open (1 of
    // 35,947 on bunny>res2, 1 of 5,205 on dragon-res4>dragon, 576 of
    // 437,645 on dragon>res2 on lavapipe, docs/bench/surfaces), and the
    // second settled them on those rows, so such a call waits once.
    [[nodiscard]] std::vector<double> start() const;
    [[nodiscard]] double cover() const { return m_cover; }
    // The radii of the next submission after one whose last radius was
    // `last` and searched `searched` of the `queries`, settling `settled`
    // of them (empty when none is left open or `last` is the cover radius):
    // up to kTailRadii, the last of them at most cover.
    [[nodiscard]] std::vector<double> next(double last, uint64_t queries, uint64_t searched,
                                           uint64_t settled) const;
    static constexpr size_t kTailRadii = 2;

private:
    double m_first = 0.0, m_cover = 0.0;
};

class SurfaceSearch {
public:
    explicit SurfaceSearch(Workspace& ws) : m_ws(ws) {}

    // queries: the points in the search frame; corners: a, b, c of every
    // triangle in the same frame (3 per triangle). Fewer than 2^30
    // triangles and 2^32 queries; a BLAS past the device's
    // maxPrimitiveCount throws gpu::LimitError. `cancel` is read between
    // submissions (true: throws CallCancelled). Vulkan failures throw.
    [[nodiscard]] SurfaceCandidates run(std::span<const glm::vec3> queries,
                                        std::span<const glm::vec3> corners,
                                        const std::atomic<bool>* cancel = nullptr);
    // Frees the buffers kept between calls (GpuHausdorff::releaseScratch).
    void release();

private:
    struct Stats;
    // The queries, corners and the triangles' tight boxes (search cells of
    // one triangle each) written to the upload buffer on the worker pool,
    // with the statistics of the radii; the device buffers grown.
    Stats stage(std::span<const glm::vec3> queries, std::span<const glm::vec3> corners);
    // The upload buffer's copies and every query's best set to none.
    void cmdUpload(VkCommandBuffer cmd);
    // One submission: its radii (each: grown boxes, BLAS build or refit,
    // rays), then every query's best copied for the host. Returns what each
    // radius did.
    std::vector<sh::SurfaceRadiusCount> submitRadii(VkCommandBuffer cmd, std::span<const double> radii,
                                                    double settledBefore, SurfaceCandidates& out);
    void cmdRadius(VkCommandBuffer cmd, double radius, double settled2, bool update, VkDeviceAddress counts);

    Workspace& m_ws;
    uint32_t m_queries = 0, m_triangles = 0;
    double m_rayTMax = 0.0;
    bool m_built = false;  // the BLAS of this call is built (the next radius refits it)
    gpu::Buffer m_points, m_corners, m_boxes, m_best, m_aabbs, m_staging, m_readback, m_counts;
};

}  // namespace rthdist::gpu_algo
