#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 3: exact minimum over the points of each candidate (query, search
// cell) pair, breaking off once a point is strictly closer than the running
// maximum.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { RefinePush pc; };

void main() {
    uint p = gl_GlobalInvocationID.x;
    uint numPairs = min(UintBuf(pc.counters).v[1], pc.pairCapacity);
    if (p >= numPairs) return;
    uvec2 pair = Uvec2Buf(pc.pairs).v[p];
    uint qi = UintBuf(pc.activeList).v[pair.x];
    StateBuf state = StateBuf(pc.state);
    if (state.v[qi].status == RTHDIST_DEAD) return;
    vec3 q = Vec4Buf(pc.queries).v[qi].xyz;
    float thr = deadThreshold(U64Buf(pc.maxPacked), pc.lowerBound2);
    // The search cell is scanned through its level-0 cells; one whose box is
    // farther than the best distance known for q (from earlier pairs, the
    // representatives, or this scan) cannot hold q's NN and is skipped.
    float bound = packedDist2(state.v[qi].best);
    uint f0 = UintBuf(pc.fineFirst).v[pair.y];
    uint f1 = pair.y + 1u < pc.numSearchCells ? UintBuf(pc.fineFirst).v[pair.y + 1u] : pc.numFineCells;
    CellBuf fine = CellBuf(pc.fineCells);
    Vec4Buf targets = Vec4Buf(pc.targets);
    float best = uintBitsToFloat(0x7f800000u);
    uint bestT = 0;
    bool dead = false;
    for (uint f = f0; f < f1 && !dead; ++f) {
        Cell c = fine.v[f];
        if (boxDist2(q, c.lo, c.hi) > min(bound, best)) continue;
        for (uint t = c.first; t < c.first + c.count; ++t) {
            vec4 tv = targets.v[t];
            float d2 = dist2(q, tv.xyz);
            uint t_ = floatBitsToUint(tv.w);
            // Ties go to the smallest target index, as in the CPU backend.
            if (d2 < best || (d2 == best && t_ < bestT)) {
                best = d2;
                bestT = t_;
                if (best < thr) {
                    dead = true;
                    break;
                }
            }
        }
    }
    if (best == uintBitsToFloat(0x7f800000u)) return;
    atomicMin(state.v[qi].best, packDistIndex(best, bestT));
}
