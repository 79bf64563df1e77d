#version 460
#extension GL_GOOGLE_include_directive : require
// After an iteration at radius R: a query whose best is within R has its exact
// NN (everything within R was scanned) and may raise h; one whose best is
// strictly below the threshold dies; the others go on with rLo = R. A query
// that lost pairs to a full buffer (RETRY) goes on with its old rLo.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { ResolvePush pc; };

void main() {
    uint slot = gl_GlobalInvocationID.x;
    if (slot >= pc.numActive) return;
    uint qi = UintBuf(pc.activeList).v[slot];
    StateBuf state = StateBuf(pc.state);
    QueryState st = state.v[qi];
    float best = packedDist2(st.best);
    U64Buf maxPacked = U64Buf(pc.maxPacked);
    float thr = deadThreshold(maxPacked, pc.lowerBound2);
    if (st.status == RTHDIST_DEAD || best < thr) {
        state.v[qi].status = RTHDIST_DEAD;
        return;
    }
    if (st.status != RTHDIST_RETRY && best <= pc.radius * pc.radius) {
        state.v[qi].status = RTHDIST_EXACT;
        atomicMax(maxPacked.v[0], packDistIndex(best, qi));
        return;
    }
    if (st.status != RTHDIST_RETRY) state.v[qi].rLo = pc.radius;
    state.v[qi].status = RTHDIST_OPEN;
    uint next = atomicAdd(UintBuf(pc.counters).v[2], 1u);
    UintBuf(pc.nextActive).v[next] = qi;
}
