// Route::kSurfaceGpu (api/route_planner.hpp): a point set against a
// triangle surface on a GPU backend (design.md §11, "The GPU backends").
// Both inputs are shifted by the centre of their union's box, scaled by a
// power of two (|coordinate| <= 1) and rounded to float; the backend's
// device search (gpu_algo/surface_search.hpp) gives each query a nearest
// triangle (a few far queries it hands back open); api/surface_certify.hpp
// measures those exactly and proves the directed maximum from the caller's
// coordinates in double; with per-point distances it also hands back every
// query's entry (the rule in double to its triangle, within the tolerance
// of design.md §11 "Per-point distances"), the slivers measured on the host
// (api/surface_slivers.hpp) and 16 queries checked exactly (a failure:
// every query recomputed by the CPU backend).
#pragma once

#include <glm/vec3.hpp>

#include "api/backend.hpp"
#include "core/input_frame.hpp"
#include "core/uninit_vector.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::api {

// The device's frame: the centre of the union of two boxes, then a power
// of two that brings every coordinate in them to at most 1 in magnitude
// (the rule's degree-4 products stay far from float's range at any input
// scale). A point is (p - origin) * scale, rounded to float.
struct SearchFrame {
    glm::dvec3 origin{0.0};
    double scale = 1.0;

    SearchFrame(const core::Bounds& a, const core::Bounds& b);
    [[nodiscard]] glm::vec3 operator()(const glm::dvec3& p) const { return glm::vec3((p - origin) * scale); }
};

// The points, or the triangles' corners (3 per triangle, in index order),
// in the frame, on the worker pool (threads as EngineOptions::threads).
[[nodiscard]] core::UninitVector<glm::vec3> framedPoints(const PointView& points, const SearchFrame& frame,
                                                         int threads);
[[nodiscard]] core::UninitVector<glm::vec3> framedCorners(const MeshView& surface, const SearchFrame& frame,
                                                          int threads);

// What the checks of a point-to-surface call found (api/surface.cpp):
// both inputs' summaries and the largest |coordinate| over both.
struct SurfaceInputs {
    core::SetSummary a, b;
    double magnitude = 0.0;
};

// Inputs checked by the caller; `device`: a GPU backend, opened for this
// call or kept by an Engine (its buffers stay for the next call). Fills
// every stage of SurfaceResult::stages but setup (the caller's). spare
// (may be null): arrays the per-point entries are written into (moved out
// of it; Engine::recycle).
[[nodiscard]] Result<SurfaceResult> surfaceOnGpu(ComputeBackend& device, const PointView& points,
                                                 const MeshView& surface, const SurfaceInputs& inputs,
                                                 const SurfaceOptions& options,
                                                 SurfacePerPoint* spare = nullptr);

}  // namespace rthdist::api
