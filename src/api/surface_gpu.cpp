#include "api/surface_gpu.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "api/surface_certify.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"
#include "core/uninit_vector.hpp"

namespace rthdist::api {

SearchFrame::SearchFrame(const core::Bounds& a, const core::Bounds& b) {
    const glm::dvec3 lo = glm::min(a.lo, b.lo), hi = glm::max(a.hi, b.hi);
    origin = (lo + hi) * 0.5;
    const glm::dvec3 half = glm::max(hi - origin, origin - lo);
    const double m = std::max({half.x, half.y, half.z});
    int exponent = 0;
    if (m > 0.0 && std::isfinite(m)) std::frexp(m, &exponent);  // m < 2^exponent
    scale = std::ldexp(1.0, -exponent);
}

// (UninitVector: first touched by the workers, its block reused by the next call.)
core::UninitVector<glm::vec3> framedPoints(const PointView& points, const SearchFrame& frame, int threads) {
    core::UninitVector<glm::vec3> out(points.count);
    core::parallelChunks(points.count, core::balancedChunk(points.count, threads), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t i = begin; i < end; ++i) out[i] = frame(points.at(i));
                         });
    return out;
}

core::UninitVector<glm::vec3> framedCorners(const MeshView& surface, const SearchFrame& frame, int threads) {
    core::UninitVector<glm::vec3> out(3 * surface.triangleCount());
    const size_t triangles = surface.triangleCount();
    core::parallelChunks(triangles, core::balancedChunk(triangles, threads, 1 << 10), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t t = begin; t < end; ++t) {
                                 for (int k = 0; k < 3; ++k)
                                     out[3 * t + size_t(k)] = frame(surface.corner(t, k));
                             }
                         });
    return out;
}

Result<SurfaceResult> surfaceOnGpu(ComputeBackend& device, const PointView& points, const MeshView& surface,
                                   const SurfaceInputs& inputs, const SurfaceOptions& options) {
    const core::Clock::time_point start = core::Clock::now();
    const SearchFrame frame(inputs.a.box, inputs.b.box);
    const core::UninitVector<glm::vec3> queries = framedPoints(points, frame, options.threads);
    const core::UninitVector<glm::vec3> corners = framedCorners(surface, frame, options.threads);
    const double frameMs = core::msSince(start);
    Result<TriangleCandidates> found = device.nearestTriangles(queries, corners, options.cancel);
    if (!found) return found.error();
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed))
        return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceOptions::cancel)"};

    const core::Clock::time_point certifyStart = core::Clock::now();
    Result<SurfaceResult> result = certifySurface(points, surface, inputs.magnitude, found->triangle, options,
                                                  found->open, found->distance2, frame.scale);
    if (!result) return result.error();
    SurfaceResult& r = result.value();
    r.backend = device.kind();
    r.device = device.deviceName();
    SurfaceCounters& n = r.directed.counters;
    n.radii = found->radii;
    n.rays = found->rays;
    n.submissions = found->submissions;
    n.tailQueries = found->tailQueries;
    n.tailHostQueries = found->open.size();
    n.tailTreeReused = found->tailTreeReused ? 1u : 0u;
    n.triangles = surface.triangleCount();
    r.stages.frame = frameMs;
    r.stages.upload = found->stageMs;
    r.stages.search = found->submitMs;
    r.stages.readback = found->readbackMs;
    r.stages.certify = core::msSince(certifyStart);
    r.stages.gpuBuild = found->gpuBuildMs;
    r.stages.tailBuild = found->tailBuildMs;
    r.stages.gpuTail = found->tailGpuMs;
    r.gpuMs = found->gpuMs;
    r.buildMs = 0.0;  // the device's setup, the caller's to add (the band's BVH is certify's)
    r.searchMs = core::msSince(start);
    r.validationMessages = device.validationMessages();
    return result;
}

}  // namespace rthdist::api
