#version 460
#extension GL_GOOGLE_include_directive : require
// After the neighbourhood pass: OPEN queries that can still raise h become the
// active list of the candidate search; the rest die.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CompactPush pc; };

void main() {
    uint qi = gl_GlobalInvocationID.x;
    if (qi >= pc.nq) return;
    uint64_t state = pc.state;
    if (stateAt(state, qi).v.status != RTHDIST_OPEN) return;
    float thr = deadThreshold(pc.maxPacked, pc.lowerBound2);
    if (packedDist2(stateAt(state, qi).v.best) < thr) {
        stateAt(state, qi).v.status = RTHDIST_DEAD;
        return;
    }
    uint slot = atomicAdd(UintRef(pc.counters + RTHDIST_CTR_ACTIVE).v, 1u);
    uintAt(pc.activeList, slot).v = qi;
}
