#include "api/surface_gpu.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <span>
#include <vector>

#include "api/surface_certify.hpp"
#include "api/surface_slivers.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/surface_search.hpp"

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

core::FramedQueries framedQueries(const PointView& points, const SearchFrame& frame) {
    core::FramedQueries queries;
    queries.count = points.count;
    queries.write = [&points, &frame](size_t begin, size_t end, glm::vec4* out) {
        for (size_t i = begin; i < end; ++i) out[i - begin] = glm::vec4(frame(points.at(i)), 0.0f);
    };
    return queries;
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

uint64_t newCornersVersion() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
}

double KeptGpuSurface::take(const MeshView& surface, const core::SetSummary& summary, bool same,
                            int threads) {
    if (!same) {
        frame.reset();
        tree.reset();
        mesh.keep(surface, summary, threads);
        return 0.0;
    }
    if (tree || surface.triangleCount() > kKeptBvhTriangles) return 0.0;
    const core::Clock::time_point start = core::Clock::now();
    tree.emplace(surface, threads);
    return core::msSince(start);
}

Result<SurfaceResult> surfaceOnGpu(ComputeBackend& device, const PointView& points, const MeshView& surface,
                                   const SurfaceInputs& inputs, const SurfaceOptions& options,
                                   SurfacePerPoint* spare, KeptGpuSurface* kept) {
    const core::Clock::time_point start = core::Clock::now();
    const SearchFrame frame(inputs.a.box, inputs.b.box);
    const core::FramedQueries queries = framedQueries(points, frame);
    core::UninitVector<glm::vec3> ownCorners;
    if (kept == nullptr) {
        ownCorners = framedCorners(surface, frame, options.threads);
    } else if (!(kept->frame && *kept->frame == frame)) {
        kept->frame.reset();  // (until its corners are framed)
        kept->corners = framedCorners(surface, frame, options.threads);
        kept->frame = frame;
        kept->version = newCornersVersion();
    }
    const std::span<const glm::vec3> corners = kept != nullptr ? kept->corners : ownCorners;
    const uint64_t version = kept != nullptr ? kept->version : 0;
    const double frameMs = core::msSince(start);
    Result<TriangleCandidates> found = device.nearestTriangles(queries, corners, options.cancel, version);
    if (!found) return found.error();
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed))
        return Error{ErrorCode::kCancelled, "the call was cancelled (SurfaceOptions::cancel)"};

    const core::Clock::time_point certifyStart = core::Clock::now();
    // Per-point entries: every U(q) with its triangle's closest point
    // (EveryQueryBound::perPoint), the flagged triangles measured on the
    // host, then the device's check on a sample.
    SurfacePerPoint perPoint;
    if (spare != nullptr) perPoint = std::move(*spare);
    EveryQueryBound every;
    every.perPoint = &perPoint;
    SurfaceOptions proofOptions = options;
    proofOptions.perPointDistances = false;
    Result<SurfaceResult> result =
        certifySurface(points, surface, inputs.magnitude, found->triangle, proofOptions, found->open,
                       found->distance2, frame.scale, options.perPointDistances ? &every : nullptr,
                       kept != nullptr && kept->tree ? &*kept->tree : nullptr, &found->tops);
    if (!result) return result.error();
    uint64_t hostTriangles = 0;
    bool recomputed = false;
    const core::Clock::time_point perPointStart = core::Clock::now();
    if (options.perPointDistances) {
        hostTriangles = measureSlivers(points, surface, corners, frame.scale, result->hausdorff,
                                       inputs.magnitude, options.threads, perPoint);
        if (perPointSamplesAgree(points, surface, perPoint, inputs.magnitude, options.threads)) {
            result->perPoint = std::move(perPoint);
        } else {
            // A sample outside the float search's bound: the device is not
            // what the bound assumes, so none of its entries is used.
            result = cpu::surfaceSearch(points, surface, inputs.magnitude, options);
            if (!result) return result.error();
            recomputed = true;
        }
    }
    const double perPointMs = options.perPointDistances ? core::msSince(perPointStart) : 0.0;
    SurfaceResult& r = result.value();
    r.stages.perPoint = perPointMs;
    r.directed.counters.cpuRecomputed = recomputed ? 1u : 0u;
    r.directed.counters.hostTriangles = hostTriangles;
    r.backend = device.kind();
    r.device = device.deviceName();
    SurfaceCounters& n = r.directed.counters;
    n.radii = found->radii;
    n.rays = found->rays;
    n.submissions = found->submissions;
    n.tailQueries = found->tailQueries;
    n.tailHostQueries = found->open.size();
    n.tailTreeReused = found->tailTreeReused ? 1u : 0u;
    n.tailLanes = found->tailLanes;
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
