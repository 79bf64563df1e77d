// rthdist — exact distances from a point set to a triangle surface
// (issue 34, phase 1: the CPU backend).
//
// Contract
//   For every point q of `points`, d(q) = min over the triangles T of the
//   surface of |q - closest(q, T)|, closest(q, T) the point of T nearest to
//   q; the directed Hausdorff distance h(points, surface) = max over q of
//   d(q), with its witness: the query, the triangle, the closest point and
//   its barycentric coordinates. Unsigned; the surface is the union of its
//   triangles (no inside, no orientation).
//   EXACT as for point sets (design.md §1, §11): the reported d(q) and h
//   equal (==) a brute force in double over EVERY triangle that measures
//   each triangle by the one shared rule (shaders/shared/
//   rthdist_point_triangle.h, core/point_triangle.hpp) in the caller's
//   coordinates; the search (a BVH over the triangles' boxes, in double)
//   prunes a box only when it lies farther than the best distance plus a
//   bound on every rounding of the rule, so it never drops the triangle the
//   brute force would pick. Ties: the smallest triangle index among a
//   query's equally near triangles, the smallest query index among the
//   queries realizing h (the brute force's order). The witness query is
//   checked against a brute force over all triangles before the result is
//   returned (a mismatch is kInternal, never a value).
//
// Precision: the rule runs in double on the coordinates as given (float
//   inputs are exact in double). A closest point is a point of the triangle
//   up to rounding (~1e-16 of the coordinates' magnitude: 1e-10 m at UTM
//   magnitudes of 1e6 m); a point exactly at a vertex measures exactly 0, as
//   does one on an edge or face at dyadic barycentric coordinates.
//   Degenerate triangles (zero area: repeated or collinear vertices) are
//   measured by their edges, and a sliver's closest point is a convex
//   combination of its vertices (never outside it).
//
// Inputs: points as for hausdorff() (finite, non-empty); a MeshView
//   (mesh.hpp) with at least one triangle, fewer than 2^32 vertices and
//   triangles, indices in range, finite vertices; every coordinate of both
//   at most 2^250 (~1.8e75) in magnitude, so that the rule's products stay
//   finite. Violations: kInvalidArgument (kBadInput for NaN/Inf), naming
//   the set, the vertex or the triangle.
//
// Backends: Backend::kAuto and kCpu run on the CPU backend (a GPU call
//   opens its device per call, so auto keeps the CPU). kRayQuery and
//   kRtPipeline search on the device (design.md §11, "The GPU backends"):
//   triangle boxes in a BLAS grown by a radius, each query's nearest
//   triangle measured by the same rule in float; the directed maximum is
//   then proven on the host in double (the queries whose float nearest
//   triangle measures in double at or above the largest query's exact
//   value are searched again exactly by the CPU backend's BVH), so the
//   value and witness are the same as on the CPU backend (==), whatever
//   the float search found. perPointDistances on a GPU backend is
//   kInvalidArgument (per-point values come from the CPU backend for now).
//
// Threading: reentrant; the search (on a GPU backend: the proof) runs on
//   SurfaceOptions::threads threads of the library's worker pool.
// Memory: at most 132 bytes per triangle (its corners in double and at
//   most one 56-byte BVH node), plus 44 bytes per point with
//   perPointDistances. GPU backends: on the device 104 bytes per triangle
//   and 24 per point (and the BLAS), on the host 36 per triangle and 24
//   per point more.
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/mesh.hpp"
#include "rthdist/options.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist {

struct SurfaceOptions {
    Backend backend = Backend::kAuto;  // kAuto or kCpu (above)
    int threads = 0;                   // 0: every hardware thread
    // Also return every point's distance, triangle and closest point
    // (SurfaceResult::perPoint). Every query then needs its own nearest
    // triangle: the early break against the running maximum is off.
    bool perPointDistances = false;
    // Read at every chunk of 256 queries: true -> kCancelled.
    const std::atomic<bool>* cancel = nullptr;
    // GPU backends: the Vulkan device (listDevices() index; -1: the first
    // that runs the backend) and the validation layer, whose messages are
    // counted (SurfaceResult::validationMessages), as EngineOptions.
    int deviceIndex = -1;
    bool validation = false;
};

// What the search did (diagnostics; not part of the exactness contract).
struct SurfaceCounters {
    uint64_t queries = 0;
    uint64_t triangles = 0;
    uint64_t bvhNodes = 0;
    uint64_t nodesVisited = 0;     // BVH nodes whose box was tested, over all queries
    uint64_t trianglesTested = 0;  // point-triangle evaluations, over all queries
    uint64_t dominated = 0;        // queries stopped early: a triangle nearer than the running maximum
    // GPU backends: the device search and the host's proof.
    uint32_t radii = 0;  // radii searched on the device
    uint64_t rays = 0;   // rays cast over all radii
    uint64_t band = 0;   // queries searched again exactly on the host (the others are proven below h)
};

// h(points, surface) with its witness.
struct SurfaceDirected {
    double distance = 0.0;         // = |queryPoint - surfacePoint| in double
    uint64_t queryIndex = 0;       // into the points
    uint32_t triangle = 0;         // into the triangles (MeshView::indices / 3)
    glm::dvec3 queryPoint{0.0};    // the input's coordinates, in double
    glm::dvec3 surfacePoint{0.0};  // closest point of that triangle
    glm::dvec3 barycentric{0.0};   // of surfacePoint w.r.t. the triangle's vertices, in index order
    SurfaceCounters counters;
};

// Every point's nearest triangle (perPointDistances), in point order.
struct SurfacePerPoint {
    std::vector<double> distance;
    std::vector<uint32_t> triangle;
    std::vector<glm::dvec3> closest;
};

struct SurfaceResult {
    double hausdorff = 0.0;  // = directed.distance: h(points, surface), directed only
    SurfaceDirected directed;
    SurfacePerPoint perPoint;
    Backend backend = Backend::kCpu;  // the backend that ran
    std::string device;               // "cpu", or the device's name
    double buildMs = 0.0;             // the BVH over the triangles
    double searchMs = 0.0;            // every query's nearest triangle (and the witness's check)
    double totalMs = 0.0;             // the whole call, checks included
    // GPU backends: device setup, the device's search and the host's proof
    // (buildMs: the device and its pipelines; searchMs: the rest).
    double gpuMs = 0.0;               // device time of the search
    uint64_t validationMessages = 0;  // with SurfaceOptions::validation
};

// h(points, surface): the points' distances to the surface and the largest
// of them with its witness (contract above).
[[nodiscard]] RTHDIST_API Result<SurfaceResult> hausdorffToSurface(PointView points, MeshView surface,
                                                                   const SurfaceOptions& options = {});

}  // namespace rthdist
