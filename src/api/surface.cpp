// Public entry of the point-to-surface distance (rthdist/surface.hpp), one-
// shot and on an Engine (api/surface_engine.hpp): the route chosen
// (api::planSurfaceRoute: the CPU backend or the device), the inputs
// checked (shape, finite coordinates, triangle indices, the rule's
// magnitude limit), then the CPU backend's search (cpu/surface_search.hpp),
// or on a GPU backend the device's search proven on the host
// (api/surface_gpu.hpp) on the Engine's device or, one-shot, on a device
// opened while the inputs are checked.
#include "rthdist/surface.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "api/route_planner.hpp"
#include "api/surface_engine.hpp"
#include "api/surface_gpu.hpp"
#include "core/input_frame.hpp"
#include "core/mesh_checks.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"
#include "cpu/surface_search.hpp"

namespace rthdist {
namespace {

// Every coordinate of both inputs at most 2^250 in magnitude: the rule's
// degree-4 products of differences stay finite (rthdist_point_triangle.h).
constexpr double kMaxSurfaceMagnitude = 0x1p250;

double magnitudeOf(const core::Bounds& box) {
    const glm::dvec3 m = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    return std::max({m.x, m.y, m.z});
}

std::optional<Error> checkMagnitude(const core::Bounds& box, const char* name) {
    const double m = magnitudeOf(box);
    if (m <= kMaxSurfaceMagnitude) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument, std::string(name) + ": a coordinate of magnitude " +
                                                  std::to_string(m) +
                                                  " is past the point-to-surface limit of 2^250 (~1.8e75)"};
}

// Every check of a call's inputs, in the order the errors are reported.
// `keptB`: the summary of a mesh equal to one checked before (an Engine's
// kept mesh, bit for bit): its triangles and vertices are not read again.
Result<api::SurfaceInputs> checkInputs(const PointView& points, const MeshView& surface, int threads,
                                       const core::SetSummary* keptB = nullptr) {
    if (auto err = core::checkShape(points, "A")) return *err;
    if (auto err = core::checkShape(surface.vertices, "B")) return *err;
    if (keptB == nullptr) {
        if (auto err = core::checkTriangles(surface, "surface B", threads)) return *err;
    }
    Result<core::SetSummary> a = core::summarizeSet(points, "A", threads);
    if (!a) return a.error();
    Result<core::SetSummary> b = keptB != nullptr ? Result<core::SetSummary>(*keptB)
                                                  : core::summarizeSet(surface.vertices, "B", threads);
    if (!b) return b.error();
    if (auto err = checkMagnitude(a->box, "point set A")) return *err;
    if (auto err = checkMagnitude(b->box, "point set B")) return *err;
    return api::SurfaceInputs{*a, *b, std::max(magnitudeOf(a->box), magnitudeOf(b->box))};
}

// Whether both views are readable (their shapes checked), so that a kept
// mesh may be compared with the call's before the inputs are checked.
bool readable(const PointView& points, const MeshView& surface) {
    return !core::checkShape(points, "A") && !core::checkShape(surface.vertices, "B");
}

}  // namespace

Result<SurfaceResult> hausdorffToSurface(PointView points, MeshView surface, const SurfaceOptions& options) {
    const core::Clock::time_point start = core::Clock::now();
    if (options.threads < 0) return Error{ErrorCode::kInvalidArgument, "threads must be >= 0"};
    const api::Plan plan = api::planSurfaceRoute(options.backend);
    if (plan.route == api::Route::kRefused) return Error{plan.code, plan.reason};
    // A GPU call's device opens on another thread while the inputs are checked.
    std::future<api::OneShotBackend> opening;
    if (plan.route == api::Route::kSurfaceGpu)
        opening = api::openOneShot(options.backend, options.deviceIndex, options.validation, options.threads);
    Result<api::SurfaceInputs> inputs = checkInputs(points, surface, options.threads);
    if (!inputs) return inputs.error();  // bad input first, even where no device opens
    Result<SurfaceResult> result = Error{ErrorCode::kInternal, "no route"};
    if (plan.route == api::Route::kSurfaceGpu) {
        api::OneShotBackend device = opening.get();
        if (!device.backend) return device.backend.error();
        result = api::surfaceOnGpu(*device.backend.value(), points, surface, *inputs, options);
        if (result) result->buildMs = device.ms;
    } else {
        result = cpu::surfaceSearch(points, surface, inputs->magnitude, options);
    }
    if (result) result->totalMs = core::msSince(start);
    return result;
}

namespace api {

Result<SurfaceResult> surfaceOnEngine(ComputeBackend& backend, const EngineOptions& engine,
                                      cpu::KeptSurfaceTree& kept, KeptGpuSurface& keptGpu,
                                      const PointView& points, const MeshView& surface,
                                      const SurfaceCallOptions& call, SurfacePerPoint& spare) {
    const core::Clock::time_point start = core::Clock::now();
    SurfaceOptions options;
    static_cast<SurfaceCallOptions&>(options) = call;
    options.backend = engine.backend;
    options.threads = engine.threads;
    // The Engine's requested backend picks the route; under kAuto the call's
    // shape, where the Engine keeps a GPU device (autoSurfaceOnGpu).
    SurfaceShape shape;
    shape.queries = points.count;
    shape.triangles = surface.triangleCount();
    shape.perPoint = call.perPointDistances;
    shape.keptDevice = backend.kind() != Backend::kCpu;
    const Plan plan = planSurfaceRoute(engine.backend, shape);
    if (plan.route == Route::kRefused) return Error{plan.code, plan.reason};
    if (plan.route == Route::kSurfaceGpu) {
        // A mesh equal to the kept one (compared once the views are
        // readable) is not checked again, and its framed corners serve
        // where the frame is the same.
        const bool same = readable(points, surface) && keptGpu.mesh.holds(surface, options.threads);
        Result<SurfaceInputs> inputs =
            checkInputs(points, surface, options.threads, same ? &keptGpu.mesh.summary() : nullptr);
        if (!inputs) return inputs.error();
        const double treeMs = keptGpu.take(surface, inputs->b, same, options.threads);
        Result<SurfaceResult> result = surfaceOnGpu(backend, points, surface, *inputs, options,
                                                    call.perPointDistances ? &spare : nullptr, &keptGpu);
        if (result) result->buildMs = treeMs;  // the proof's BVH where built (0: kept or none)
        if (result) result->totalMs = core::msSince(start);
        return result;
    }
    // The CPU route: a mesh equal to the kept one (compared once the views
    // are readable) is neither checked nor built again.
    const core::Clock::time_point treeStart = core::Clock::now();
    const bool reused = readable(points, surface) && kept.holds(surface, options.threads);
    double treeMs = core::msSince(treeStart);
    Result<SurfaceInputs> inputs =
        checkInputs(points, surface, options.threads, reused ? &kept.summary() : nullptr);
    if (!inputs) return inputs.error();
    const core::Clock::time_point buildStart = core::Clock::now();
    const cpu::TriangleBvh& tree = reused ? kept.tree() : kept.keep(surface, inputs->b, options.threads);
    treeMs += core::msSince(buildStart);
    Result<SurfaceResult> result =
        cpu::surfaceSearch(points, surface, inputs->magnitude, options, tree, &kept.blocks(),
                           call.perPointDistances ? &spare : nullptr);
    if (!result) return result;
    result->buildMs = treeMs;  // the tree's build, or the comparison that kept it
    result->directed.counters.tailTreeReused = reused ? 1 : 0;
    result->totalMs = core::msSince(start);
    return result;
}

}  // namespace api
}  // namespace rthdist
