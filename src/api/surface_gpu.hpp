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

#include <cstddef>
#include <cstdint>
#include <optional>

#include "api/backend.hpp"
#include "core/framed_queries.hpp"
#include "core/input_frame.hpp"
#include "core/kept_mesh.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/triangle_bvh.hpp"
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
    [[nodiscard]] bool operator==(const SearchFrame&) const = default;
};

// The points as a search's queries, framed by the search itself straight
// into its upload buffer (core::FramedQueries; `points` and `frame` must
// outlive the search). The triangles' corners (3 per triangle, in index
// order) in the frame, on the worker pool (threads as EngineOptions::threads).
[[nodiscard]] core::FramedQueries framedQueries(const PointView& points, const SearchFrame& frame);
[[nodiscard]] core::UninitVector<glm::vec3> framedCorners(const MeshView& surface, const SearchFrame& frame,
                                                          int threads);

// A name for one set of framed corners, never given to another
// (ComputeBackend::nearestTriangles' cornersVersion): from one counter of
// the process, so no two Engines or calls share one.
[[nodiscard]] uint64_t newCornersVersion();

// An Engine's GPU route between its calls (api/surface.cpp's
// surfaceOnEngine): its last mesh (a copy, bit for bit: core::KeptMesh),
// and the corners of that mesh framed as the frame says, with their
// version. A call whose mesh the copy holds and whose frame is the same
// (the same boxes give the same frame) takes those corners as they are:
// no framing, and the device keeps the tree it built from them without
// comparing them again (design.md §11, "A kept mesh"). From the second call
// of the same mesh it also keeps a BVH over its triangles
// (cpu::TriangleBvh), which the proof's exact measures take instead of a
// pass over every triangle (for at most kKeptBvhTriangles: past it the
// pass stays, and no BVH is kept). Memory: the copy, 24 bytes a vertex and
// 12 a triangle, the corners, 36 bytes a triangle, and the BVH (~60-100
// bytes a triangle), until another mesh (or, for the corners, frame)
// replaces them.
inline constexpr size_t kKeptBvhTriangles = size_t(1) << 24;
struct KeptGpuSurface {
    core::KeptMesh mesh;
    std::optional<SearchFrame> frame;  // of `corners`; none: no corners kept (the mesh changed)
    core::UninitVector<glm::vec3> corners;
    uint64_t version = 0;
    std::optional<cpu::TriangleBvh> tree;  // of `mesh`; none until its second call

    // The call's mesh `surface` (checked; `summary` its vertices'): where it
    // is not the kept one (`same` false) kept in its place, its corners and
    // BVH dropped; where it is, its BVH built if none is kept yet (within
    // kKeptBvhTriangles). Returns the milliseconds of that build (0: none).
    double take(const MeshView& surface, const core::SetSummary& summary, bool same, int threads);
};

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
// of it; Engine::recycle). kept (may be null: one-shot): an Engine's, its
// mesh `surface` (the caller keeps it and resets its frame when the mesh
// changes); its corners are reused where the frame is the same, else
// framed and kept with a new version.
[[nodiscard]] Result<SurfaceResult> surfaceOnGpu(ComputeBackend& device, const PointView& points,
                                                 const MeshView& surface, const SurfaceInputs& inputs,
                                                 const SurfaceOptions& options,
                                                 SurfacePerPoint* spare = nullptr,
                                                 KeptGpuSurface* kept = nullptr);

}  // namespace rthdist::api
