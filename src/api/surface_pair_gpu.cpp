#include "api/surface_pair_gpu.hpp"

#include <cmath>
#include <string>

#include "api/surface_certify.hpp"

namespace rthdist::api {

DeviceSampleSearch::DeviceSampleSearch(ComputeBackend& device, const MeshView& to, const SearchFrame& frame,
                                       double magnitude, int threads, const std::atomic<bool>* cancel)
    : m_device(device),
      m_to(to),
      m_frame(frame),
      m_magnitude(magnitude),
      m_threads(threads),
      m_cancel(cancel),
      m_corners(framedCorners(to, frame, threads)),
      m_cornersVersion(newCornersVersion()) {}

Result<size_t> DeviceSampleSearch::search(std::span<const glm::dvec3> points, std::span<double> distance,
                                          std::span<uint32_t> nearest) {
    const PointView view(points);
    Result<TriangleCandidates> found =
        m_device.nearestTriangles(framedQueries(view, m_frame), m_corners, m_cancel, m_cornersVersion);
    if (!found) return found.error();
    m_gpuMs += found->gpuMs;
    if (m_cancel != nullptr && m_cancel->load(std::memory_order_relaxed))
        return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceBoundsOptions::cancel)"};
    SurfaceOptions proofOptions;
    proofOptions.threads = m_threads;
    proofOptions.cancel = m_cancel;
    EveryQueryBound every;
    // (No device distances: every U(q) is measured, so none would be skipped.)
    Result<SurfaceResult> proof =
        certifySurface(view, m_to, m_magnitude, found->triangle, proofOptions, found->open, {}, 0.0, &every);
    if (!proof) return proof.error();
    // Every sample's U (the rule in double to its candidate; an open one's
    // exact nearest) and that triangle, as the proof measured them.
    for (size_t i = 0; i < points.size(); ++i) {
        if (!std::isfinite(every.bound2[i]))
            return Error{ErrorCode::kInternal, "surface to surface: the device search left sample " +
                                                   std::to_string(i) + " without a triangle"};
        distance[i] = std::sqrt(every.bound2[i]);
        nearest[i] = every.triangle[i];
    }
    // The proven maximum: the exact distance and nearest triangle.
    const auto k = size_t(proof->directed.queryIndex);
    distance[k] = proof->directed.distance;
    nearest[k] = proof->directed.triangle;
    return k;
}

}  // namespace rthdist::api
