#include "api/surface_gpu.hpp"

#include <glm/common.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "api/surface_certify.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
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

namespace {

// The float rule's own error on a triangle the per-point entries trust
// (design.md §11, "Per-point distances"), in the frame's units: with the
// frame's rounding (below 2^-18) it stays under kSearchedReach.
constexpr double kRuleErrorBound = 0x1p-17;

// Whether the float rule may measure triangle (a, b, c) (the device's float
// corners, in the frame) farther than kRuleErrorBound from the double rule.
// Its signed areas, of degree 4, carry absolute errors ~u_f L^3 D (L its
// longest edge, D the query's distance, at most the frame's diameter 2
// sqrt(3)); divided by their sum |n|^2 they move the closest point by up to
// u_f L^4 D / |n|^2 along the triangle (never past it: a convex
// combination). Well-shaped triangles (|n| ~ L^2) stay near u_f D; a
// sliver (|n| = L w, w its width) reaches its own length once w^2 ~ u_f L D.
// Flagged (with a factor 4): those past the bound, and zero area (n = 0 in
// float) unless the three corners are one point.
bool illConditioned(const glm::vec3& fa, const glm::vec3& fb, const glm::vec3& fc) {
    const glm::dvec3 a(fa), b(fb), c(fc);
    const double l2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    if (l2 == 0.0) return false;  // one point: its distance is a vertex's
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double n2 = glm::dot(n, n);
    constexpr double kFrameDiameter = 3.4641016151377546;  // 2 sqrt(3)
    return !(4.0 * 0x1p-24 * kFrameDiameter * l2 * l2 * std::sqrt(l2) <= kRuleErrorBound * n2);
}

// Per-point entries: the triangles the float rule may mismeasure are
// measured for every query in double by the CPU backend's search over them
// alone, and a query whose candidate they beat (or tie with a smaller
// index) takes theirs, its device distance set from the exact one. The
// others' candidates keep what the float search found (within its bound).
// Returns how many triangles were measured so.
Result<uint64_t> measureIllConditioned(const PointView& points, const MeshView& surface,
                                       std::span<const glm::vec3> corners, const SearchFrame& frame,
                                       double magnitude, const SurfaceOptions& options,
                                       TriangleCandidates& found) {
    const size_t triangles = surface.triangleCount();
    const size_t chunk = core::balancedChunk(triangles, options.threads, 1 << 10);
    std::vector<std::vector<uint32_t>> parts((triangles + chunk - 1) / chunk);
    core::parallelChunks(triangles, chunk, options.threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            if (illConditioned(corners[3 * t], corners[3 * t + 1], corners[3 * t + 2]))
                parts[begin / chunk].push_back(uint32_t(t));
        }
    });
    const std::vector<uint32_t> flagged = core::concatenateParts<std::vector<uint32_t>>(parts);
    if (flagged.empty()) return uint64_t(0);
    std::vector<uint32_t> indices;
    indices.reserve(3 * flagged.size());
    for (const uint32_t t : flagged) {
        for (size_t k = 0; k < 3; ++k) indices.push_back(surface.indices[3 * size_t(t) + k]);
    }
    SurfaceOptions exact;
    exact.backend = Backend::kCpu;
    exact.threads = options.threads;
    exact.cancel = options.cancel;
    exact.perPointDistances = true;
    Result<SurfaceResult> near =
        cpu::surfaceSearch(points, MeshView{surface.vertices, indices}, magnitude, exact);
    if (!near) return near.error();
    const SurfacePerPoint& p = near->perPoint;
    const double reach = kSearchedReach / frame.scale;
    const double scale2 = frame.scale * frame.scale;
    core::parallelChunks(
        points.count, core::balancedChunk(points.count, options.threads), options.threads,
        [&](size_t begin, size_t end, int) {
            for (size_t q = begin; q < end; ++q) {
                const uint32_t mine = flagged[p.triangle[q]];
                const uint32_t t = found.triangle[q];
                const float f2 = found.distance2[q];
                double u2 = std::numeric_limits<double>::infinity();
                if (t < triangles) {
                    // Past the candidate's U for sure: nothing to compare.
                    if (f2 >= 0.0f && std::sqrt(double(f2)) / frame.scale + reach < p.distance[q]) continue;
                    u2 = core::closestOnTriangle(points.at(q), surface.corner(t, 0), surface.corner(t, 1),
                                                 surface.corner(t, 2))
                             .distance2;
                }
                const double d2 = core::closestOnTriangle(points.at(q), surface.corner(mine, 0),
                                                          surface.corner(mine, 1), surface.corner(mine, 2))
                                      .distance2;
                if (d2 < u2 || (d2 == u2 && mine < t)) {
                    found.triangle[q] = mine;
                    found.distance2[q] = float(d2 * scale2);
                }
            }
        });
    return uint64_t(flagged.size());
}

}  // namespace

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
    uint64_t hostTriangles = 0;
    if (options.perPointDistances) {
        Result<uint64_t> measured =
            measureIllConditioned(points, surface, corners, frame, inputs.magnitude, options, found.value());
        if (!measured) return measured.error();
        hostTriangles = *measured;
    }
    // Per-point entries: every U(q) with its triangle's closest point, then
    // the device's check on a sample (EveryQueryBound::perPoint).
    SurfacePerPoint perPoint;
    EveryQueryBound every;
    every.perPoint = &perPoint;
    SurfaceOptions proofOptions = options;
    proofOptions.perPointDistances = false;
    Result<SurfaceResult> result =
        certifySurface(points, surface, inputs.magnitude, found->triangle, proofOptions, found->open,
                       found->distance2, frame.scale, options.perPointDistances ? &every : nullptr);
    if (!result) return result.error();
    bool recomputed = false;
    if (options.perPointDistances && every.samplesAgree) {
        result->perPoint = std::move(perPoint);
    } else if (options.perPointDistances) {
        // A sample outside the float search's bound: the device is not what
        // the bound assumes, so none of its entries is used.
        result = cpu::surfaceSearch(points, surface, inputs.magnitude, options);
        if (!result) return result.error();
        recomputed = true;
    }
    SurfaceResult& r = result.value();
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
