// Shared between C++ (src/gpu_algo/surface_search.cpp) and GLSL
// (surface_search*.r*, surface_search_rq.comp, surface_tail.comp): the push
// constants of the point-to-surface search (design.md §11). One procedural
// AABB per triangle, grown by the radius; each query keeps its nearest
// triangle so far as one packed word (float bits of the squared distance
// << 32 | triangle), lowered with atomicMin: the smaller distance wins, then
// the smaller triangle. The device's answer is a candidate only: the host
// proves the value in double (api/surface_certify.hpp).
#ifndef RTHDIST_SURFACE_SEARCH_H
#define RTHDIST_SURFACE_SEARCH_H

#include "rthdist_shared.h"

#ifdef __cplusplus
namespace rthdist::shared {
#endif

// The packed word of a query that has no triangle yet (its distance bits
// are a NaN: no comparison settles it).
#define RTHDIST_SURFACE_NONE 0xffffffffffffffffUL

// What one radius did, for the host's next step (one per radius of a
// submission, in host-visible memory): the queries it searched (open
// before it) and, of those, the ones it settled (best within the radius).
struct SurfaceRadiusCount {
    uint searched;
    uint settled;
};

struct SurfaceSearchPush {
    uint64_t queries;  // vec4[numQueries]: the points in the search frame
    uint64_t corners;  // vec4[3 * triangles]: a, b, c of each triangle in the search frame
    uint64_t best;     // uint64[numQueries]: the packed nearest triangle so far
    uint64_t counts;   // SurfaceRadiusCount of this radius (atomicAdd)
    uint numQueries;
    float radius;    // triangles whose box lies within it are visited
    float settled2;  // a query whose best is at most this was settled by an earlier radius
    float settle2;   // a best at most this after this radius settles the query (counted)
    float rayTMax;
    uint slotBase;  // rt-pipeline: first query of this trace (traces are split by the device's limit)
    uint mutant;    // 1: core::searchMutant (tests only): every third triangle is skipped
    uint pad;
};

// The tail (surface_tail.comp): every query the radii left open descends
// the float BVH of the triangles (gpu_algo/surface_tree.hpp) nearest-first,
// measuring each triangle of a leaf it reaches by the rays' own test
// (surface_visit.glsl's visitCorners) on the corners the tree holds in its
// own order (`leafCorners`: a leaf's triangles read from consecutive
// records, no index to follow first).
#define RTHDIST_SURFACE_TAIL_STACK 32  // at least the tree's levels less one (kSurfaceTreeMaxLevels)

struct SurfaceTailPush {
    uint64_t queries;  // vec4[numQueries]: the points in the search frame
    uint64_t best;     // uint64[numQueries]: the packed nearest triangle so far, lowered in place
    uint64_t nodes;    // Cell[]: the tree, root first (surface_tree.hpp)
    // uvec4[3 * triangles]: the corners a, b, c (float bits in xyz) of the
    // triangle at each sorted position of the tree; a's w holds its index.
    uint64_t leafCorners;
    uint64_t counts;   // uint: the queries the tail searched (atomicAdd)
    uint numQueries;
    float settled2;  // a query whose best is at most this was settled by the radii
    uint mutant;     // 1: core::searchMutant (tests only): every third triangle is skipped
    uint laneBits;   // 2^laneBits threads a query (surface_tail.comp; gpu_algo::tailLaneBits)
};

#ifdef __cplusplus
static_assert(sizeof(SurfaceTailPush) == 56);
static_assert(offsetof(SurfaceTailPush, counts) == 32);
static_assert(offsetof(SurfaceTailPush, numQueries) == 40);
static_assert(offsetof(SurfaceTailPush, mutant) == 48);
static_assert(sizeof(SurfaceRadiusCount) == 8);
static_assert(sizeof(SurfaceSearchPush) == 64);
static_assert(offsetof(SurfaceSearchPush, numQueries) == 32);
static_assert(offsetof(SurfaceSearchPush, settle2) == 44);
static_assert(offsetof(SurfaceSearchPush, slotBase) == 52);
}  // namespace rthdist::shared
#endif
#endif
