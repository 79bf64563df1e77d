#include "cpu/sample_search.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace rthdist::cpu {

BvhSampleSearch::BvhSampleSearch(const MeshView& to, double slack, int threads,
                                 const std::atomic<bool>* cancel)
    : m_bvh(to, threads), m_slack(slack), m_threads(threads), m_cancel(cancel) {}

Result<size_t> BvhSampleSearch::search(std::span<const glm::dvec3> points, std::span<double> distance,
                                       std::span<uint32_t> nearest) {
    std::atomic<bool> cancelled{false};
    core::parallelChunks(points.size(), core::heavyItemChunk(points.size(), m_threads), m_threads,
                         [&](size_t lo, size_t hi, int) {
                             if (m_cancel != nullptr && m_cancel->load(std::memory_order_relaxed)) {
                                 cancelled.store(true, std::memory_order_relaxed);
                                 return;
                             }
                             for (size_t i = lo; i < hi; ++i) {
                                 const NearestTriangle hit = m_bvh.nearest(points[i], m_slack);
                                 distance[i] = std::sqrt(hit.distance2);
                                 nearest[i] = hit.triangle;
                             }
                         });
    if (cancelled.load())
        return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceBoundsOptions::cancel)"};
    // Every distance is exact: the first largest.
    return size_t(std::max_element(distance.begin(), distance.begin() + ptrdiff_t(points.size())) -
                  distance.begin());
}

}  // namespace rthdist::cpu
