// The point-to-surface search's test of one candidate triangle, shared by
// the ray-query and the ray-tracing-pipeline paths and the tail (design.md
// §11). Expects `pc` to be a SurfaceSearchPush (or, with
// RTHDIST_SURFACE_VISIT_CORNERS_ONLY defined, any push with `mutant`). A
// triangle whose box is farther than the query's best so far cannot be
// nearer and is skipped; the others are
// measured by the one shared rule (rthdist_point_triangle.h, in float
// here) and lower the packed best: the smaller distance, then the smaller
// triangle. Nothing here decides the reported value: the host measures the
// answer again in double (api/surface_certify.hpp).
#include "rthdist_point_triangle.h"

// Triangle t of corners a, b, c (the rays read them by index, the tail
// from the tree's own copy: the same floats).
void visitCorners(vec3 q, uint t, vec3 a, vec3 b, vec3 c, inout uint64_t best) {
    if (pc.mutant != 0u && t % 3u == 0u) return;  // tests only: a search that misses triangles
    // NaN (no best yet) compares false: the triangle is measured.
    if (boxDist2(q, min(min(a, b), c), max(max(a, b), c)) > packedDist2(best)) return;
    vec3 closest, bary;
    float d2 = pointTriangleClosest(q, a, b, c, closest, bary);
    uint64_t packed = packDistIndex(d2, t);
    if (packed < best) best = packed;
}

#ifndef RTHDIST_SURFACE_VISIT_CORNERS_ONLY  // (the tail's push has no `corners`)
void visitTriangle(vec3 q, uint t, inout uint64_t best) {
    visitCorners(q, t, vec4At(pc.corners, 3u * t).v.xyz, vec4At(pc.corners, 3u * t + 1u).v.xyz,
                 vec4At(pc.corners, 3u * t + 2u).v.xyz, best);
}
#endif
