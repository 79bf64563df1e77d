#version 460
#extension GL_GOOGLE_include_directive : require
// The point-to-surface search, ray-query path: one ray of tiny length per
// query not yet settled, over the BLAS of the triangles' boxes grown by the
// radius; every AABB candidate is measured (surface_visit.glsl). Counts
// the queries it searched and those it settled (SurfaceRadiusCount).
#extension GL_EXT_ray_query : require
#include "common.glsl"
#include "rthdist_surface_search.h"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SurfaceSearchPush pc; };
layout(set = 0, binding = 0) uniform accelerationStructureEXT u_tlas;
#include "surface_visit.glsl"

void main() {
    uint qi = gl_GlobalInvocationID.x;
    if (qi >= pc.numQueries) return;
    uint64_t best = u64At(pc.best, qi).v;
    if (packedDist2(best) <= pc.settled2) return;
    atomicAdd(uintAt(pc.counts, 0u).v, 1u);
    vec3 q = vec4At(pc.queries, qi).v.xyz;
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, u_tlas, gl_RayFlagsNoneEXT, 0xff, q, 0.0, vec3(1.0, 0.0, 0.0), pc.rayTMax);
    while (rayQueryProceedEXT(rq)) {
        if (rayQueryGetIntersectionTypeEXT(rq, false) == gl_RayQueryCandidateIntersectionAABBEXT)
            visitTriangle(q, rayQueryGetIntersectionPrimitiveIndexEXT(rq, false), best);
    }
    u64At(pc.best, qi).v = best;
    if (packedDist2(best) <= pc.settle2) atomicAdd(uintAt(pc.counts, 1u).v, 1u);
}
