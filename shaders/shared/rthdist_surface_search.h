// Shared between C++ (src/gpu_algo/surface_search.cpp) and GLSL
// (surface_search*.r*, surface_search_rq.comp): the push constants of the
// point-to-surface search (design.md §11). One procedural AABB per
// triangle, grown by the radius; each query keeps its nearest triangle so
// far as one packed word (float bits of the squared distance << 32 |
// triangle), lowered with atomicMin: the smaller distance wins, then the
// smaller triangle. The device's answer is a candidate only: the host
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

struct SurfaceSearchPush {
    uint64_t queries;   // vec4[numQueries]: the points in the search frame
    uint64_t corners;   // vec4[3 * triangles]: a, b, c of each triangle in the search frame
    uint64_t best;      // uint64[numQueries]: the packed nearest triangle so far
    uint64_t searched;  // uint: queries this radius searched (atomicAdd)
    uint numQueries;
    float radius;    // triangles whose box lies within it are visited
    float settled2;  // a query whose best is at most this was settled by an earlier radius
    float rayTMax;
    uint slotBase;  // rt-pipeline: first query of this trace (traces are split by the device's limit)
    uint mutant;    // 1: core::searchMutant (tests only): every third triangle is skipped
};

#ifdef __cplusplus
static_assert(sizeof(SurfaceSearchPush) == 56);
static_assert(offsetof(SurfaceSearchPush, numQueries) == 32);
static_assert(offsetof(SurfaceSearchPush, slotBase) == 48);
}  // namespace rthdist::shared
#endif
#endif
