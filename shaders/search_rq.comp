#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 2 (ray-query path): one ray of tiny length per active query over the
// BLAS of grown cell boxes; every AABB candidate gets the exact test.
#extension GL_EXT_ray_query : require
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SearchPush pc; };
layout(set = 0, binding = 0) uniform accelerationStructureEXT u_tlas;
#include "search_visit.glsl"

void main() {
    uint slot = gl_GlobalInvocationID.x;
    if (slot >= searchedCount(pc.counters, pc.numActive)) return;
    uint qi = uintAt(pc.activeList, slot).v;
    if (waitsForItsClass(qi)) return;
    vec3 q = vec4At(pc.queries, qi).v.xyz;
    QueryState st = stateAt(pc.state, qi).v;
    float rLo = st.rLo;
    float bestLocal = packedDist2(st.best);
    float thr = deadThreshold(pc.maxPacked, pc.lowerBound2);
    rayQueryEXT rq;
    rayQueryInitializeEXT(rq, u_tlas, gl_RayFlagsNoneEXT, 0xff, q, 0.0, vec3(1.0, 0.0, 0.0), pc.rayTMax);
    while (rayQueryProceedEXT(rq)) {
        if (rayQueryGetIntersectionTypeEXT(rq, false) == gl_RayQueryCandidateIntersectionAABBEXT) {
            uint cellIndex = rayQueryGetIntersectionPrimitiveIndexEXT(rq, false);
            if (visitCell(slot, qi, q, rLo, thr, cellIndex, bestLocal)) rayQueryTerminateEXT(rq);
        }
    }
}
