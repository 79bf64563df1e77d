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
    StateBuf state = StateBuf(pc.state);
    if (state.v[qi].status != RTHDIST_OPEN) return;
    float thr = deadThreshold(U64Buf(pc.maxPacked), pc.lowerBound2);
    if (packedDist2(state.v[qi].best) < thr) {
        state.v[qi].status = RTHDIST_DEAD;
        return;
    }
    uint slot = atomicAdd(UintBuf(pc.counters).v[0], 1u);
    UintBuf(pc.activeList).v[slot] = qi;
}
