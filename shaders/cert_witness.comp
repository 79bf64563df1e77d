#version 460
#extension GL_GOOGLE_include_directive : require
// The certificate's brute force of the witness (core/certificate.hpp),
// recorded with the final self-check so that a band of one query (the
// usual case) costs no submission of its own: the witness's slot and float
// maximum come from the counter block, and every target within
// (sqrt(max) + 4e)^2, rounded up, is appended: the witness's float distance
// is within e of its exact bound U, so that holds every target within U + 3e,
// the bound the host gives a band query (certificate_pass.cpp). One read of
// the targets, a grid-stride loop: any number of groups covers them (the
// dispatch behind the search takes the check's indirect groups).
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CertWitnessPush pc; };

shared vec4 entry;

void main() {
    if (pc.afterCull != 0u && UintRef(pc.counters + RTHDIST_CTR_ACTIVE).v != 0u) return;
    if (gl_LocalInvocationID.x == 0u) {
        uint64_t packed = U64Ref(pc.counters + RTHDIST_CTR_MAX_PACKED).v;
        uint slot = min(uint(packed & 0xffffffffu), pc.queryCount - 1u);
        vec4 q = vec4At(pc.queries, slot).v;
        float reach = (sqrt(packedDist2(packed)) + 4.0 * pc.slack) * (1.0 + 1.0 / 1048576.0);
        entry = vec4(q.xyz, reach * reach * (1.0 + 1.0 / 1048576.0));
        if (gl_WorkGroupID.x == 0u) {
            UintRef(pc.found).v = 1u;
            UintRef(pc.found + 4ul).v = floatBitsToUint(q.w);
        }
    }
    barrier();
    const uint step = gl_NumWorkGroups.x * RTHDIST_WG;
    for (uint t = gl_GlobalInvocationID.x; t < pc.n; t += step) {
        const vec4 p = vec4At(pc.targets, t).v;
        if (dist2(entry.xyz, p.xyz) <= entry.w) {
            const uint j = atomicAdd(UintRef(pc.found + 8ul).v, 1u);
            if (j < pc.capacity) uintAt(pc.found + 16ul, j).v = floatBitsToUint(p.w);
        }
    }
}
