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
//   inputs are exact in double), and in 113-bit arithmetic for a thin
//   triangle whose normal double would lose (design.md §11 "Thin
//   triangles"). A closest point is a point of the triangle up to rounding
//   and its distance within a few u of the coordinates' magnitude m of the
//   exact one (~1e-16 m: 1e-10 m at UTM magnitudes of 1e6 m), slivers
//   included; a point exactly at a vertex measures exactly 0, as does one
//   on an edge or face at dyadic barycentric coordinates where the corners'
//   differences are exact in double (else within the rounding above).
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
// Backends: Backend::kAuto and kCpu run on the CPU backend (a one-shot GPU
//   call opens its device per call, so auto keeps the CPU). kRayQuery and
//   kRtPipeline search on the device (design.md §11, "The GPU backends"):
//   triangle boxes in a BLAS grown by a radius, each query's nearest
//   triangle measured by the same rule in float; the directed maximum is
//   then proven on the host in double (the queries whose float nearest
//   triangle measures in double at or above the largest query's exact
//   value are searched again exactly by the CPU backend's BVH), so the
//   value and witness are the same as on the CPU backend (==), whatever
//   the float search found. perPointDistances on a GPU backend: every
//   point's entry is the rule in double to the triangle the float search
//   found for it, within SurfacePerPoint::tolerance of its exact nearest
//   distance (never below it), the witness's entry the proven one; a
//   sample of 16 points is measured exactly by the brute force on every
//   such call as the device's check, and where one falls outside the
//   tolerance every point is measured by the CPU backend instead
//   (SurfaceCounters::cpuRecomputed, tolerance 0).
//
// On a kept device: Engine::hausdorffToSurface (rthdist.hpp) runs the same
//   call on an Engine's backend, which keeps its device, pipelines, upload
//   and search buffers and BLAS storage between calls (a one-shot GPU call
//   creates them all: ~0.35 s on an H200). The route is the Engine's
//   EngineOptions::backend's as above: kRayQuery and kRtPipeline search on
//   its device (per-point distances within the tolerance, as above), kCpu
//   runs the CPU backend. kAuto runs the CPU backend too, except on an
//   Engine that chose a GPU device, where a call without per-point
//   distances that has at least 2^14 points and at least as many points as
//   the mesh has triangles searches on the device (the sizes where the kept
//   GPU route was measured faster on an H200 with 16 host threads; its
//   value and witness are the CPU backend's, ==; SurfaceResult::backend
//   names the one that ran). The results
//   are those of hausdorffToSurface with the same backend (==); threads are
//   EngineOptions::threads. On the CPU backend an Engine keeps its last
//   mesh's BVH with a copy of that mesh (24 bytes a vertex, 12 a
//   triangle): a call whose mesh equals it, compared exactly (every
//   vertex's value bit for bit, every index; float or double alike),
//   searches the kept tree (SurfaceCounters::tailTreeReused = 1, buildMs the
//   comparison's), any other builds and keeps a new one. A GPU backend
//   uploads its inputs afresh and keeps its tail's tree for the same
//   corners; its buffers only grow, to the largest call's, until the
//   Engine is destroyed. Engine::recycle(SurfaceResult&&) hands a spent
//   result's per-point arrays to the Engine's next per-point call.
//
// Threading: reentrant; the BVH build and the search (on a GPU backend: the
//   framing and the proof) run on SurfaceOptions::threads threads of the
//   library's worker pool. The BVH, and so every result, is the same on
//   any thread count. An Engine serves one call at a time (as compute).
// Memory: at most 112 bytes per triangle (its corners, 72 bytes in double
//   or 36 in float for a float mesh; at most one 32-byte BVH node; its
//   index, twice during the build), plus 60 bytes per point with
//   perPointDistances (SurfacePerPoint). GPU backends: on the device 104
//   bytes per triangle and 24 per point (and the BLAS); on the host 36 per
//   triangle and 16 per point, and host-visible upload and read-back
//   buffers of 80 per triangle and 24 per point (kept by an Engine).
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

// What may change from call to call (Engine::hausdorffToSurface).
struct SurfaceCallOptions {
    // Also return every point's distance, triangle, closest point and
    // barycentric coordinates (SurfaceResult::perPoint: exact on the CPU
    // backend, within its tolerance on a GPU backend). Every query then
    // needs its own nearest triangle: the early break against the running
    // maximum is off.
    bool perPointDistances = false;
    // With perPointDistances: fill only SurfacePerPoint::distance and
    // ::triangle, leaving closest and barycentric empty (the evaluation's
    // use, rthdist/eval.hpp: 12 bytes a point instead of 60). Ignored
    // without perPointDistances.
    bool perPointDistancesOnly = false;
    // Read at every chunk of 256 queries (GPU backends: also before and
    // between the device's submissions): true -> kCancelled. An Engine
    // stays usable after a cancelled call.
    const std::atomic<bool>* cancel = nullptr;
};

// The one-shot call's options: the call's, and what an Engine fixes for
// its life (EngineOptions' backend, threads, deviceIndex, validation).
struct SurfaceOptions : SurfaceCallOptions {
    Backend backend =
        Backend::kAuto;  // above: kAuto or kCpu on the CPU, kRayQuery or kRtPipeline on a device
    int threads = 0;     // 0: every hardware thread
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
    uint32_t radii = 0;        // radii searched on the device
    uint64_t rays = 0;         // rays cast over all radii
    uint32_t submissions = 0;  // command buffers the search submitted and waited for
    // The queries the radii left open (design.md §11, "The tail") go one of
    // two ways: many descend the device's tree of the triangles (the tail),
    // a few (open queries x triangles at most Tuning::surfaceHostWork) are
    // measured exactly on the host instead (no tree, one submission).
    uint64_t tailQueries = 0;      // queries searched by the device's tree descent
    uint64_t tailHostQueries = 0;  // queries measured exactly on the host instead (the proof's brute force)
    // 1: the tree was the call before's, not built: a GPU backend's descent
    // tree (same corners), or an Engine's CPU-backend BVH (the same mesh).
    uint32_t tailTreeReused = 0;
    // Threads that shared each query's descent of the device's tree (1 to
    // 32; 0 where no query descended): more where few queries descend. The
    // answer is the same whatever their number. RTHDIST_SURFACE_TAIL_LANES.
    uint32_t tailLanes = 0;
    // Queries searched again exactly on the host (the others are proven below h).
    uint64_t band = 0;
    // Per-point distances on a GPU backend: 1 where a sample of the device's
    // entries failed its check (SurfacePerPoint), and every point was then
    // measured by the CPU backend instead (exact, tolerance 0).
    uint32_t cpuRecomputed = 0;
    // Per-point distances on a GPU backend: the triangles the float rule may
    // measure too far off (slivers, design.md §11 "Per-point distances"),
    // measured for every point in double on the host instead.
    uint64_t hostTriangles = 0;
};

// Where a GPU backend's call went, in milliseconds of host wall clock
// unless named gpu (all 0 on the CPU backend). searchMs = frame + upload +
// search + readback + certify, up to the code between them.
struct SurfaceStages {
    double frame = 0.0;      // inputs shifted, scaled, rounded to float (worker pool; not a kept mesh,
                             // and a point-to-surface call's queries are framed in `upload`)
    double upload = 0.0;     // queries framed into the upload buffer, corners and boxes written (worker pool)
    double search = 0.0;     // the device's submissions, waited for: the upload's copies, every
                             // radius's boxes, BLAS build or refit and rays, the read-back's copy;
                             // where queries are left open, the tail (tree built, descent, copies)
    double readback = 0.0;   // every query's candidate triangle taken from the read-back buffer
    double certify = 0.0;    // the proof in double (the band's exact search included)
    double gpuBuild = 0.0;   // device time of the boxes and BLAS builds and refits (part of gpuMs)
    double tailBuild = 0.0;  // the tail's tree of the triangles built on the host (part of search)
    double gpuTail = 0.0;    // device time of the tail's tree descent and its copies (part of gpuMs)
    double tailHost = 0.0;   // the open queries measured exactly on the host instead (part of certify)
    double perPoint =
        0.0;  // per-point entries: slivers measured on the host, the sample check (part of certify)
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

// Every point's nearest triangle (perPointDistances), in point order; empty
// without it. Each entry is what SurfaceDirected holds for the witness, for
// every point: distance[i] = |point i - closest[i]| in double, equal (==)
// to the brute force over every triangle (the contract above), triangle[i]
// its nearest triangle (the smallest index on a tie), closest[i] the
// closest point of that triangle and barycentric[i] its coordinates w.r.t.
// the triangle's vertices in index order (non-negative, summing to 1 up to
// rounding; closest = the vertices weighted by them, up to rounding).
// SurfaceDirected's entry is the same as the arrays' at its queryIndex.
// On a GPU backend (tolerance > 0) each entry is the rule in double to the
// triangle the device's float search found for the point (design.md §11,
// "Per-point distances"): triangle[i], closest[i] and barycentric[i] are
// that triangle's, distance[i] = |point i - closest[i]| in double, and
// d(i) <= distance[i] <= d(i) + tolerance, d(i) the brute force's nearest
// distance (equal to it, with the brute force's triangle, wherever no
// other triangle lies within the tolerance of the nearest; the witness's
// entry always). The tolerance is 2^-15 of the search frame's unit, the
// power of two just above the half-extent of both inputs' box: at most
// 2^-14 (6.1e-5) of that half-extent (3.8e-6 m for the Stanford bunny,
// 0.16 m across).
struct SurfacePerPoint {
    std::vector<double> distance;
    std::vector<uint32_t> triangle;
    std::vector<glm::dvec3> closest;
    std::vector<glm::dvec3> barycentric;
    double tolerance = 0.0;  // 0: every entry exact (the CPU backend)
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
    // GPU backends: buildMs is the device and its pipelines created for a
    // one-shot call; on an Engine, which keeps them, the BVH over the mesh
    // that the proof's exact measures take, built on the second call of a
    // mesh (0 on the others); searchMs the rest, split in `stages`.
    SurfaceStages stages;
    double gpuMs = 0.0;               // device time of the search
    uint64_t validationMessages = 0;  // with SurfaceOptions::validation (an Engine's: over its life)
};

// h(points, surface): the points' distances to the surface and the largest
// of them with its witness (contract above). On a GPU backend the device
// is created while the inputs are checked and destroyed with the call;
// Engine::hausdorffToSurface keeps it.
[[nodiscard]] RTHDIST_API Result<SurfaceResult> hausdorffToSurface(PointView points, MeshView surface,
                                                                   const SurfaceOptions& options = {});

// ---------------------------------------------------------------------------
// Surface to surface (issue 34: the CPU backend and both GPU backends)
//
// Contract
//   H(SA, SB) = max(h(SA, SB), h(SB, SA)) between the surfaces of two meshes,
//   h(SA, SB) = max over EVERY point p of SA's triangles (not only the
//   vertices) of d(p, SB), d as in hausdorffToSurface. A continuum has no
//   brute force, so the answer is a pair of CERTIFIED bounds in real
//   arithmetic: lower <= H <= upper and upper - lower <= the tolerance.
//   lower is realized by a witness: a point of SA (or SB) and its closest
//   point on the other surface, found by the exact point-to-surface search;
//   lower = the witness's distance less the rounding slack below (0 at
//   least). upper holds for every point of the surfaces: each triangle is
//   split into patches (four by its edge midpoints, recursively) until every
//   patch's upper bound is within the tolerance of the best lower bound. A
//   patch's bound is the smaller of (design.md §12):
//   - convexity (Tang, Lee & Kim 2009): d(., t) is convex for any triangle
//     t of the other surface, so over the patch d <= d(., t) <= the largest
//     of d(corner, t); t runs over the nearest triangles of the corners (and
//     of the centroid, queried when the corners' bound is not enough);
//   - Lipschitz: d is 1-Lipschitz, and every point of a triangle lies within
//     2/3 of its longest edge of one corner: d <= max corner d + 2/3 edge
//     (with the centroid c: d(c) + the largest |corner - c|).
//   Each round queries the new corners and centroids in one batch on the
//   worker pool (the exact nearest-triangle search of hausdorffToSurface).
//   The bounds of each direction are certified too, but only H's (or with
//   directedOnly h(SA, SB)'s) width is held to the tolerance: a patch is
//   settled once it cannot raise H past lower + tolerance.
//
// Precision: the work runs in a frame centred on the box of both meshes
//   (translation does not change H; the shift rounds each vertex by at most
//   2^-53 of its distance to the centre). slack = 2^-40 m, m the largest
//   |coordinate| in that frame, exceeds every rounding of the rule, of the
//   midpoints (exact dyadic barycentric coordinates, rounded once per level)
//   and of the edge lengths by a factor above 16 (design.md §12); lower and
//   upper each carry it. Witness points are reported in the input's frame
//   (shifted back, rounded once).
//
// Inputs: two MeshViews as for hausdorffToSurface (at least one triangle
//   each, indices in range, finite coordinates at most 2^250). Vertices that
//   no triangle uses are not part of a surface. tolerance: an absolute
//   distance, finite; 0 (default) is 1e-4 of the diagonal of the box of both
//   meshes' vertices; it must be at least 4 slack (2^-38 m: ~4e-12 of the
//   meshes' extent), else kInvalidArgument naming the floor (1e-6 of the
//   diagonal is reachable unless the box is flatter than 1e-5 of its
//   longest side). maxQueries bounds the point-to-surface queries (the
//   memory: 40 bytes each, plus 16 per open patch); a call that would need
//   more is kOutOfMemory naming the bounds reached and the limit.
//
// Backends and threading as hausdorffToSurface: kAuto and kCpu run each
//   round's batch on the CPU backend's BVH (every sample's distance exact);
//   kRayQuery and kRtPipeline on the device's float search of
//   hausdorffToSurface (one device opened for the call, both directions on
//   it): each sample's distance is the rule in double to the triangle the
//   device found (an upper bound of its exact distance, which the patches'
//   bounds need), each batch's maximum is proven exactly on the host (the
//   lower bound's witness), so the bounds are certified alike; they may
//   differ from the CPU backend's within the tolerance (the same lower
//   bound where the same samples are queried). A GPU backend's tolerance
//   must be at least 2^-14 of the largest coordinate of the box of both
//   meshes around its centre, rounded up to a power of two (at most
//   ~6.1e-5 of the box's diagonal, below the default), else
//   kInvalidArgument naming that floor: a sample's distance may exceed its
//   exact one by the float search's reach. Deterministic on each backend:
//   the same bounds and witnesses whatever the thread count (the rounds are
//   batches; ties go to the smaller index).
struct SurfaceBoundsOptions {
    Backend backend = Backend::kAuto;  // kAuto or kCpu on the CPU, kRayQuery or kRtPipeline on a device
    int threads = 0;                   // 0: every hardware thread
    // GPU backends: the Vulkan device and the validation layer, as SurfaceOptions.
    int deviceIndex = -1;
    bool validation = false;
    double tolerance = 0.0;     // absolute; 0: 1e-4 of the bounding diagonal
    bool directedOnly = false;  // h(SA, SB) alone
    uint64_t maxQueries = uint64_t(1) << 26;
    // Read at every chunk of queries: true -> kCancelled.
    const std::atomic<bool>* cancel = nullptr;
};

struct SurfaceBoundsCounters {
    uint64_t queries = 0;   // point-to-surface queries (corners, midpoints, centroids)
    uint64_t patches = 0;   // patch bounds evaluated
    uint64_t splits = 0;    // patches split in four
    uint64_t rounds = 0;    // batches of queries
    uint64_t maxDepth = 0;  // deepest split level reached
};

// One direction, h(from, to): its certified bounds and the witness of lower.
struct SurfaceBoundsDirected {
    double lower = 0.0, upper = 0.0;
    double distance = 0.0;            // the witness's |fromPoint - toPoint|, in the work frame
    uint32_t fromTriangle = 0;        // the triangle of `from` holding fromPoint
    glm::dvec3 fromPoint{0.0};        // on `from`'s surface, input frame
    glm::dvec3 fromBarycentric{0.0};  // of fromPoint in fromTriangle, index order
    uint32_t toTriangle = 0;          // fromPoint's nearest triangle of `to`
    glm::dvec3 toPoint{0.0};          // its closest point, input frame
    glm::dvec3 toBarycentric{0.0};
    SurfaceBoundsCounters counters;
};

struct SurfaceBoundsResult {
    double lower = 0.0, upper = 0.0;  // lower <= H <= upper, upper - lower <= tolerance
    double tolerance = 0.0;           // the tolerance used (absolute)
    double slack = 0.0;               // the rounding slack each bound carries
    glm::dvec3 origin{0.0};           // the work frame's origin in the input frame
    SurfaceBoundsDirected aToB;       // h(SA, SB)
    SurfaceBoundsDirected bToA;       // h(SB, SA); zeros with directedOnly
    bool directed = false;            // directedOnly: bounds are h(SA, SB)'s
    Backend backend = Backend::kCpu;  // the backend that ran
    std::string device;               // "cpu", or the device's name
    double buildMs = 0.0;             // the BVHs (GPU backends: every triangle's corners framed)
    double searchMs = 0.0;            // the rounds
    double totalMs = 0.0;             // the whole call (GPU backends: setupMs included)
    double setupMs = 0.0;             // GPU backends: the device opened for the call (beside the checks)
    double gpuMs = 0.0;               // GPU backends: device time of every batch's search
    uint64_t validationMessages = 0;  // with SurfaceBoundsOptions::validation
};

// Certified bounds on H(surface a, surface b) (contract above).
[[nodiscard]] RTHDIST_API Result<SurfaceBoundsResult> surfaceHausdorff(
    MeshView a, MeshView b, const SurfaceBoundsOptions& options = {});

}  // namespace rthdist
