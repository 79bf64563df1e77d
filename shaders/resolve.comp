#version 460
#extension GL_GOOGLE_include_directive : require
// After an iteration at radius R: a query whose best is within R has its exact
// NN (everything within R was scanned) and may raise h; one whose best is
// strictly below the threshold dies; the others go on with rLo = R. A query
// that lost pairs to a full buffer (RETRY) goes on with its old rLo when this
// radius searched the level the old rLo was scanned at, else with rLo = 0.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { ResolvePush pc; };

void main() {
    uint slot = gl_GlobalInvocationID.x;
    if (slot >= searchedCount(pc.counters, pc.numActive)) return;
    uint qi = uintAt(pc.activeList, slot).v;
    uint64_t state = pc.state;
    QueryState st = stateAt(state, qi).v;
    float best = packedDist2(st.best);
    uint64_t maxPacked = pc.maxPacked;
    float thr = deadThreshold(maxPacked, pc.lowerBound2);
    if (st.status == RTHDIST_DEAD || best < thr) {
        stateAt(state, qi).v.status = RTHDIST_DEAD;
        return;
    }
    if (st.status != RTHDIST_RETRY && best <= pc.radius * pc.radius) {
        stateAt(state, qi).v.status = RTHDIST_EXACT;
        raiseMax(maxPacked, packDistIndex(best, qi));
        return;
    }
    // rLo: every cell of this level within it was scanned. A query that lost
    // pairs keeps the radius before, which holds only if that radius searched
    // the same level; after a level change nothing of the new level is known
    // to be scanned (rLo = 0: search_visit.glsl then skips nothing).
    if (st.status != RTHDIST_RETRY) stateAt(state, qi).v.rLo = pc.radius;
    else if (pc.sameLevel == 0u) stateAt(state, qi).v.rLo = 0.0;
    stateAt(state, qi).v.status = RTHDIST_OPEN;
    uint next = atomicAdd(UintRef(pc.counters + RTHDIST_CTR_NEXT_ACTIVE).v, 1u);
    uintAt(pc.nextActive, next).v = qi;
}
