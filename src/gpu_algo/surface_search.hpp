// The point-to-surface search on the device (issue 34; design.md §11): the
// RT-HDIST scheme of the point search (candidate_search.hpp) with triangles
// for targets. One procedural AABB per triangle in a BLAS, its box grown by
// a radius R (refitted as R grows, in batches of radii per submission);
// one ray of tiny length per query not yet settled (ray query, or the
// ray-tracing pipeline of surface_search.rgen/rint), and every triangle
// whose grown box the ray starts in is measured by the shared rule
// (shaders/shared/rthdist_point_triangle.h) in float, the query keeping
// its nearest. A query whose nearest lies within R is settled (a nearer
// triangle's box lies within R too, so it was visited: up to float
// rounding); the others go on with 2R, up to a radius that covers the
// union of both inputs' boxes, where every query meets every triangle.
//
// The answer is a candidate, not a value: each query's nearest triangle
// (or none). The caller proves the directed maximum in double on the host
// (api/surface_certify.hpp), so a rounding or a miss here costs host work,
// never a wrong value.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.hpp"

namespace rthdist::gpu_algo {

struct Workspace;

struct SurfaceCandidates {
    std::vector<uint32_t> triangle;  // per query: its nearest triangle found, UINT32_MAX for none
    uint32_t radii = 0;              // radii searched
    uint64_t rays = 0;               // rays cast over all radii
    double gpuMs = 0.0;              // device time of the searches
};

class SurfaceSearch {
public:
    explicit SurfaceSearch(Workspace& ws) : m_ws(ws) {}

    // queries: the points in the search frame; corners: a, b, c of every
    // triangle in the same frame (3 per triangle). Fewer than 2^30
    // triangles and 2^32 queries; a BLAS past the device's
    // maxPrimitiveCount throws gpu::LimitError. Vulkan failures throw.
    [[nodiscard]] SurfaceCandidates run(std::span<const glm::vec3> queries,
                                        std::span<const glm::vec3> corners);

private:
    // The triangles' tight boxes (search cells of one triangle each), the
    // corners and the queries on the device; every query's best set to none.
    void upload(std::span<const glm::vec3> queries, std::span<const glm::vec3> corners);
    // One submission: the radii, each grown boxes, BLAS (refit after the
    // first), rays; returns the queries each radius searched.
    std::vector<uint32_t> runRadii(std::span<const double> radii, double settledBefore, bool firstBuild);
    void cmdRadius(VkCommandBuffer cmd, double radius, double settled2, bool update,
                   VkDeviceAddress searched);

    Workspace& m_ws;
    uint32_t m_queries = 0, m_triangles = 0;
    double m_rayTMax = 0.0;
    gpu::Buffer m_points, m_corners, m_boxes, m_best, m_aabbs, m_staging, m_readback, m_searched;
};

}  // namespace rthdist::gpu_algo
