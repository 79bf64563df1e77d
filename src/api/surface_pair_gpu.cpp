#include "api/surface_pair_gpu.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "api/surface_certify.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"

namespace rthdist::api {

DeviceSampleSearch::DeviceSampleSearch(ComputeBackend& device, const MeshView& to, const SearchFrame& frame,
                                       double magnitude, int threads, const std::atomic<bool>* cancel)
    : m_device(device),
      m_to(to),
      m_frame(frame),
      m_magnitude(magnitude),
      m_threads(threads),
      m_cancel(cancel),
      m_corners(framedCorners(to, frame, threads)) {}

Result<size_t> DeviceSampleSearch::search(std::span<const glm::dvec3> points, std::span<double> distance,
                                          std::span<uint32_t> nearest) {
    const PointView view(points);
    const core::UninitVector<glm::vec3> queries = framedPoints(view, m_frame, m_threads);
    Result<TriangleCandidates> found = m_device.nearestTriangles(queries, m_corners, m_cancel);
    if (!found) return found.error();
    m_gpuMs += found->gpuMs;
    if (m_cancel != nullptr && m_cancel->load(std::memory_order_relaxed))
        return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceBoundsOptions::cancel)"};
    SurfaceOptions proofOptions;
    proofOptions.threads = m_threads;
    proofOptions.cancel = m_cancel;
    std::vector<uint32_t> openNearest;
    Result<SurfaceResult> proof = certifySurface(view, m_to, m_magnitude, found->triangle, proofOptions,
                                                 found->open, found->distance2, m_frame.scale, &openNearest);
    if (!proof) return proof.error();

    // Every sample's candidate (an open one's: its exact nearest) and the
    // rule's distance to it in double.
    std::span<uint32_t> candidate(found->triangle.data(), points.size());
    for (size_t k = 0; k < found->open.size(); ++k) candidate[found->open[k]] = openNearest[k];
    const size_t triangles = m_to.triangleCount();
    std::atomic<size_t> missing{points.size()};
    core::parallelChunks(points.size(), core::balancedChunk(points.size(), m_threads), m_threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t i = begin; i < end; ++i) {
                                 const uint32_t t = candidate[i];
                                 if (t >= triangles) {
                                     missing.store(i, std::memory_order_relaxed);
                                     continue;
                                 }
                                 nearest[i] = t;
                                 distance[i] =
                                     std::sqrt(core::closestOnTriangle(points[i], m_to.corner(t, 0),
                                                                       m_to.corner(t, 1), m_to.corner(t, 2))
                                                   .distance2);
                             }
                         });
    if (missing.load() != points.size())
        return Error{ErrorCode::kInternal, "surface to surface: the device search left sample " +
                                               std::to_string(missing.load()) + " without a triangle"};
    // The proven maximum: the exact distance and nearest triangle.
    const auto k = size_t(proof->directed.queryIndex);
    distance[k] = proof->directed.distance;
    nearest[k] = proof->directed.triangle;
    return k;
}

}  // namespace rthdist::api
