// The batches of point-to-surface queries of the surface-to-surface
// refinement (cpu/surface_bounds.hpp; design.md §12): each round's new
// corners and centroids of one surface's patches against the triangles of
// the other. The refinement needs of a batch only (a) an upper bound of
// every point's exact distance d(p) to the surface, with the triangle that
// realizes it (its convexity bound measures the neighbours' triangles), and
// (b) the batch's largest exact distance with its point and nearest
// triangle, the lower bound's witness. The CPU backend's BVH answers every
// point exactly; a GPU backend's float search gives candidates whose
// distances are upper bounds and proves the maximum on the host
// (api/surface_pair_gpu.hpp).
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>

#include "cpu/triangle_bvh.hpp"
#include "rthdist/mesh.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cpu {

class SampleSearch {
public:
    virtual ~SampleSearch() = default;

    // points: in the refinement's work frame, on one surface; the other
    // surface's triangles are the search's own. Fills, for every i,
    // nearest[i] (a triangle index) and distance[i] = the shared rule's
    // distance in double from points[i] to that triangle, so distance[i] >=
    // d(points[i]) (up to the rule's rounding, core::closestSlack). Returns
    // the index k of the batch's largest exact distance: distance[k] =
    // d(points[k]) >= d(points[i]) for every i, nearest[k] its nearest
    // triangle (the smallest index on a tie), the smallest such k on a tie.
    // kCancelled when the call's cancel flag is set; any other error is the
    // backend's. points not empty.
    [[nodiscard]] virtual Result<size_t> search(std::span<const glm::dvec3> points,
                                                std::span<double> distance, std::span<uint32_t> nearest) = 0;
};

// The CPU backend's batch search: a TriangleBvh over `to` (built here, on
// `threads` as EngineOptions::threads), every point's exact nearest
// triangle, the batch in chunks on the worker pool, `cancel` read at each.
// `to` must outlive it. slack: core::closestSlack of the work frame.
class BvhSampleSearch final : public SampleSearch {
public:
    BvhSampleSearch(const MeshView& to, double slack, int threads, const std::atomic<bool>* cancel);
    [[nodiscard]] Result<size_t> search(std::span<const glm::dvec3> points, std::span<double> distance,
                                        std::span<uint32_t> nearest) override;

private:
    TriangleBvh m_bvh;
    double m_slack = 0.0;
    int m_threads = 0;
    const std::atomic<bool>* m_cancel = nullptr;
};

}  // namespace rthdist::cpu
