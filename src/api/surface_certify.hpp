// The proof of a point-to-surface answer found by a search that is not
// exact (the GPU backends' float search, gpu_algo/surface_search.hpp):
// design.md §11, "The GPU backends". Given any triangle per query (the
// search's nearest, or none), the directed maximum and its witness are
// computed exactly, equal (==) to the brute force over every triangle in
// double, whatever the candidates are:
//   1. U(q) = the shared rule in double between q and its candidate
//      (infinite without one) is at least q's exact nearest distance d(q).
//   2. q* = the query of largest U (smallest index on a tie) is measured
//      exactly: L = d(q*) <= h.
//   3. A query with U(q) < L has d(q) < L <= h: it neither realizes h nor
//      ties it. The others (the band, U(q) >= L, q* among them) are
//      measured exactly, in index order: by the brute force over the
//      triangles while the band times the triangles is small (the usual
//      band of one query; a triangle whose box lies farther than U(q) plus
//      the rounding slack of the CPU backend's BVH, core::closestSlack, is
//      skipped unmeasured: it can hold neither the nearest nor a tie),
//      else by the CPU backend's BVH search (cpu/surface_search.hpp, its
//      own proof and witness check); so the answer is h with the brute
//      force's witness (ties: smallest triangle, smallest query).
// Good candidates make the band small (the queries within the float
// search's rounding of the maximum); bad ones only make it larger.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/searched_tops.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/triangle_bvh.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::api {

// points and surface checked by the caller (api/surface.cpp); candidate:
// one triangle index per point, UINT32_MAX (or any index past the last
// triangle) for none; magnitude: the largest |coordinate| over both
// (core::closestSlack). perPointDistances is not offered (kInvalidArgument).
// open (increasing query indices): queries the search left unsettled
// (gpu_algo::SurfaceCandidates::open), measured exactly first by the same
// brute force (pruned by their candidate's U), then taking their nearest
// triangle for candidate: their U is then exact, and the proof runs as
// above (a measured query found again is not measured twice).
// SurfaceResult::directed.counters.band: the queries searched exactly in 3.;
// stages.tailHost: the open queries' brute force.
// searched2 (may be empty): the device's squared distance of each query to
// its candidate in the search frame, whose scale is `searchScale` (a power of
// two): the proof then measures U(q) only where that distance (plus a
// rounding reach, checked on a sample of the call) does not rule it out
// (surface_certify.cpp, kSearchedReach; design.md §11). The answer is the
// same either way. searchedSummary (may be null): searched2's largest by
// chunks (core::SearchedTops), as the search wrote them; used where it
// covers searched2 and no query is open, else the proof summarizes
// searched2 itself (the same q* and band either way).
// tree (may be null): a BVH over `surface`'s triangles (an Engine's kept
// one, api/surface_gpu.hpp's KeptGpuSurface): the queries measured exactly
// (the open ones, q*, the band) then take its nearest-triangle query
// instead of a pass over every triangle; the answer is the same (the
// tree's query equals the brute force, cpu/triangle_bvh.hpp).
// every (may be null): also every query's U(q) (squared) and the triangle
// that gives it, in query order: its candidate, or an open query's exact
// nearest (the brute force's). The proof then measures every U(q) (as
// without searched2), whose values it hands back instead of the caller
// measuring them again (the GPU's surface to surface, api/surface_pair_gpu.hpp).
struct EveryQueryBound {
    core::UninitVector<double> bound2;  // +inf: no triangle
    std::vector<uint32_t> triangle;
    // Where set (per-point distances on a GPU backend, api/surface_gpu.hpp):
    // also every query's entry as SurfacePerPoint holds it, from the same
    // measure (distance = sqrt(U(q)), its triangle, closest point and
    // barycentric coordinates; tolerance 2 kSearchedReach / searchScale), the
    // witness's entry the proven one. Needs the device's distances.
    SurfacePerPoint* perPoint = nullptr;
};

// The device's check of a per-point call (design.md §11, "Per-point
// distances"): kPerPointSamples queries spread over the indices measured
// exactly by the brute force in one pass over the triangles. True when
// each sample's entry lies within entries.tolerance of its exact nearest
// distance (and is not below it); a sample without a triangle fails.
inline constexpr size_t kPerPointSamples = 16;
[[nodiscard]] bool perPointSamplesAgree(const PointView& points, const MeshView& surface,
                                        const SurfacePerPoint& entries, double magnitude, int threads);

// How far the device's distance to a query's candidate, over the frame's
// scale, may lie from U(q) (surface_certify.cpp: the frame's and the float
// rule's rounding, below 2^-18, with a factor 4; checked on a sample of
// every call). Per-point entries (EveryQueryBound::perPoint) are within
// twice it of the exact distance, in the frame's units (design.md §11).
inline constexpr double kSearchedReach = 0x1p-16;
[[nodiscard]] Result<SurfaceResult> certifySurface(
    const PointView& points, const MeshView& surface, double magnitude, std::span<const uint32_t> candidate,
    const SurfaceOptions& options, std::span<const uint32_t> open = {}, std::span<const float> searched2 = {},
    double searchScale = 0.0, EveryQueryBound* every = nullptr, const cpu::TriangleBvh* tree = nullptr,
    const core::SearchedTops* searchedSummary = nullptr);

}  // namespace rthdist::api
