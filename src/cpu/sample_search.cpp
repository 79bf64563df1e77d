#include "cpu/sample_search.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace rthdist::cpu {
namespace {

// Chunks of 16 to 256 items, about four a thread: an item costs ~1 us (a
// BVH descent, a patch's bounds), so a round of a few hundred samples
// still spreads over the threads (a fixed 256 left most rounds on one).
constexpr size_t kMinChunk = 16, kMaxChunk = 256;

}  // namespace

BvhSampleSearch::BvhSampleSearch(const MeshView& to, double slack, int threads,
                                 const std::atomic<bool>* cancel)
    : m_bvh(to, threads), m_slack(slack), m_threads(threads), m_cancel(cancel) {}

Result<size_t> BvhSampleSearch::search(std::span<const glm::dvec3> points, std::span<double> distance,
                                       std::span<uint32_t> nearest) {
    std::atomic<bool> cancelled{false};
    core::parallelChunks(points.size(), core::balancedChunk(points.size(), m_threads, kMinChunk, kMaxChunk),
                         m_threads, [&](size_t lo, size_t hi, int) {
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
