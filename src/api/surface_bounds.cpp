// Public entry of surface to surface (rthdist/surface.hpp,
// surfaceHausdorff): both meshes checked (shape, finite coordinates,
// triangle indices, the rule's magnitude limit), the route chosen
// (api::planSurfaceRoute, as for point to surface), both meshes shifted to
// a frame centred on their common box (design.md §12: the slack then scales
// with the meshes' extent, not their distance from the origin), the
// tolerance resolved and checked against its floor (and a GPU backend's),
// then the refinement (cpu/surface_bounds.hpp) with each direction's batch
// search: the CPU backend's BVH, or the device's search proven on the host
// (api/surface_pair_gpu.hpp) on a device opened while the meshes are
// checked; the witnesses shifted back.
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "api/route_planner.hpp"
#include "api/surface_pair_gpu.hpp"
#include "core/input_frame.hpp"
#include "core/mesh_checks.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "core/stopwatch.hpp"
#include "cpu/surface_bounds.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {
namespace {

// As point to surface (api/surface.cpp): the rule's degree-4 products stay finite.
constexpr double kMaxMagnitude = 0x1p250;
// The default tolerance, relative to the diagonal of both meshes' box.
constexpr double kDefaultRelativeTolerance = 1e-4;

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

double magnitudeOf(const core::Bounds& box) {
    const glm::dvec3 m = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    return std::max({m.x, m.y, m.z});
}

// The mesh checked and summarized (its box), or the error naming it.
Result<core::SetSummary> checkMesh(const MeshView& mesh, const char* set, int threads) {
    const std::string name = std::string("surface ") + set;
    if (auto err = core::checkShape(mesh.vertices, set)) return *err;
    if (auto err = core::checkTriangles(mesh, name, threads)) return *err;
    Result<core::SetSummary> s = core::summarizeSet(mesh.vertices, set, threads);
    if (!s) return s.error();
    if (magnitudeOf(s->box) > kMaxMagnitude) {
        return Error{ErrorCode::kInvalidArgument, name + ": a coordinate of magnitude " +
                                                      number(magnitudeOf(s->box)) +
                                                      " is past the surface limit of 2^250 (~1.8e75)"};
    }
    return s;
}

// The mesh's vertices in the work frame: p - origin, in double (worker pool).
std::vector<glm::dvec3> shifted(const MeshView& mesh, const glm::dvec3& origin, int threads) {
    std::vector<glm::dvec3> v(mesh.vertices.count);
    core::parallelChunks(v.size(), core::balancedChunk(v.size(), threads), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t i = begin; i < end; ++i) v[i] = mesh.vertices.at(i) - origin;
                         });
    return v;
}

Result<double> resolveTolerance(double requested, double diagonal, double slack) {
    if (!std::isfinite(requested) || requested < 0.0)
        return Error{ErrorCode::kInvalidArgument,
                     "tolerance must be a finite distance >= 0, not " + number(requested)};
    const double tolerance = requested > 0.0 ? requested : kDefaultRelativeTolerance * diagonal;
    const double floor = 4.0 * slack;
    if (tolerance >= floor) return tolerance;
    return Error{
        ErrorCode::kInvalidArgument,
        "tolerance " + number(tolerance) + " is below the rounding floor " + number(floor) +
            " of these meshes (4 x 2^-40 of their largest coordinate around the centre of their box)"};
}

// A GPU backend's floor (kGpuPairFloor in the search frame's units).
std::optional<Error> checkGpuFloor(double tolerance, const api::SearchFrame& frame, Backend backend) {
    const double floor = api::kGpuPairFloor / frame.scale;
    if (tolerance >= floor) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument,
                 "tolerance " + number(tolerance) + " is below the " + backendName(backend) +
                     " backend's floor " + number(floor) +
                     " for these meshes (2^-14 of the largest coordinate of their box around its centre, "
                     "rounded up to a power of two: the float search's reach); the cpu backend reaches 4 x "
                     "2^-40 of it"};
}

void shiftBack(SurfaceBoundsDirected& d, const glm::dvec3& origin) {
    d.fromPoint += origin;
    d.toPoint += origin;
}

}  // namespace

Result<SurfaceBoundsResult> surfaceHausdorff(MeshView a, MeshView b, const SurfaceBoundsOptions& options) {
    const core::Clock::time_point start = core::Clock::now();
    if (options.threads < 0) return Error{ErrorCode::kInvalidArgument, "threads must be >= 0"};
    const api::Plan plan = api::planSurfacePairRoute(options.backend);
    if (plan.route == api::Route::kRefused) return Error{plan.code, plan.reason};
    const bool gpu = plan.route == api::Route::kSurfaceGpu;
    // A GPU call's device opens on another thread while the meshes are checked.
    std::future<api::OneShotBackend> opening;
    if (gpu)
        opening = api::openOneShot(options.backend, options.deviceIndex, options.validation, options.threads);
    Result<core::SetSummary> sa = checkMesh(a, "A", options.threads);
    if (!sa) return sa.error();
    Result<core::SetSummary> sb = checkMesh(b, "B", options.threads);
    if (!sb) return sb.error();

    const glm::dvec3 lo = glm::min(sa->box.lo, sb->box.lo), hi = glm::max(sa->box.hi, sb->box.hi);
    const glm::dvec3 origin = (lo * 0.5) + (hi * 0.5);  // halves first: no overflow near the limit
    const std::vector<glm::dvec3> va = shifted(a, origin, options.threads),
                                  vb = shifted(b, origin, options.threads);
    const core::Bounds work{lo - origin, hi - origin};
    const double magnitude = std::max(magnitudeOf(work), 0.0);
    const double slack = core::closestSlack(magnitude);
    Result<double> tolerance = resolveTolerance(options.tolerance, glm::distance(lo, hi), slack);
    if (!tolerance) return tolerance.error();
    const api::SearchFrame frame(work, work);
    if (gpu) {
        if (auto err = checkGpuFloor(*tolerance, frame, options.backend)) return *err;
    }

    const MeshView wa{PointView(va), a.indices}, wb{PointView(vb), b.indices};
    std::unique_ptr<cpu::SampleSearch> aToB, bToA;
    api::OneShotBackend device;
    if (gpu) device = opening.get();
    if (gpu && !device.backend) return device.backend.error();
    const core::Clock::time_point buildStart = core::Clock::now();
    if (gpu) {
        api::ComputeBackend& backend = *device.backend.value();
        aToB = std::make_unique<api::DeviceSampleSearch>(backend, wb, frame, magnitude, options.threads,
                                                         options.cancel);
        if (!options.directedOnly)
            bToA = std::make_unique<api::DeviceSampleSearch>(backend, wa, frame, magnitude, options.threads,
                                                             options.cancel);
    } else {
        // Both trees at once (a small mesh's build runs on one thread; a
        // large one's share the worker pool). A future of void: no
        // std::future instance over an internal type (the shared library
        // exports no such symbol, tools/package_test.sh).
        std::future<void> other;
        if (!options.directedOnly)
            other = std::async(std::launch::async, [&] {
                bToA = std::make_unique<cpu::BvhSampleSearch>(wa, slack, options.threads, options.cancel);
            });
        aToB = std::make_unique<cpu::BvhSampleSearch>(wb, slack, options.threads, options.cancel);
        if (other.valid()) other.get();
    }
    const double buildMs = core::msSince(buildStart);
    Result<SurfaceBoundsResult> result =
        cpu::surfaceBounds(wa, wb, *tolerance, slack, options, *aToB, bToA.get());
    if (!result) return result;
    result->tolerance = *tolerance;
    result->origin = origin;
    shiftBack(result->aToB, origin);
    if (!options.directedOnly) shiftBack(result->bToA, origin);
    result->buildMs = buildMs;  // both BVHs, or (GPU) both meshes' corners framed
    if (gpu) {
        api::ComputeBackend& backend = *device.backend.value();
        result->backend = backend.kind();
        result->device = backend.deviceName();
        result->setupMs = device.ms;
        for (const std::unique_ptr<cpu::SampleSearch>* s : {&aToB, &bToA}) {
            if (*s) result->gpuMs += static_cast<const api::DeviceSampleSearch&>(**s).gpuMs();
        }
        result->validationMessages = backend.validationMessages();
    } else {
        result->backend = Backend::kCpu;
        result->device = "cpu";
    }
    result->totalMs = core::msSince(start);
    return result;
}

}  // namespace rthdist
