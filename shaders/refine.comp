#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 3: exact minimum over the points of each candidate (query, search
// cell) pair, breaking off once a point is strictly closer than the running
// maximum. One thread per pair (grid-stride).
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { RefinePush pc; };

void refinePair(uint p) {
    uvec2 pair = uvec2At(pc.pairs, p).v;
    uint qi = uintAt(pc.activeList, pair.x).v;
    uint64_t state = pc.state;
    if (stateAt(state, qi).v.status == RTHDIST_DEAD) return;
    vec3 q = vec4At(pc.queries, qi).v.xyz;
    float thr = deadThreshold(pc.maxPacked, pc.lowerBound2);
    // The search cell is scanned through its level-0 cells; one whose box is
    // farther than the best distance known for q (from earlier pairs, the
    // representatives, or this scan) cannot hold q's NN and is skipped.
    float bound = packedDist2(stateAt(state, qi).v.best);
    uint f0 = pair.y, f1 = pair.y + 1u;  // level 0: the search cell is a level-0 cell
    if (pc.fineFirst != 0ul) {
        f0 = uintAt(pc.fineFirst, pair.y).v;
        f1 = pair.y + 1u < pc.numSearchCells ? uintAt(pc.fineFirst, pair.y + 1u).v : pc.numFineCells;
    }
    uint64_t fine = pc.fineCells;
    uint64_t targets = pc.targets;
    float best = uintBitsToFloat(0x7f800000u);
    uint bestT = 0;
    bool dead = false;
    // A point at distance 0 ends the scan: nothing can be closer (with
    // duplicates, the reported target is one of the query's copies).
    for (uint f = f0; f < f1 && !dead && best > 0.0; ++f) {
        Cell c = cellAt(fine, f).v;
        if (boxDist2(q, c.lo, c.hi) > min(bound, best)) continue;
        // Copies of one point: the first stands for all (no per-copy work).
        uint end = all(equal(c.lo, c.hi)) ? c.first + 1u : c.first + c.count;
        for (uint t = c.first; t < end; ++t) {
            vec4 tv = vec4At(targets, t).v;
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
                if (best == 0.0) break;
            }
        }
    }
    if (best == uintBitsToFloat(0x7f800000u)) return;
    atomicMin(stateAt(state, qi).v.best, packDistIndex(best, bestT));
}

// Dispatched indirectly (refine_args.comp sizes it from the pairs the rays
// appended, at most the device's group limit): a grid-stride loop covers
// every pair.
void main() {
    uint numPairs = uint(min(U64Ref(pc.counters + RTHDIST_CTR_PAIRS).v, uint64_t(pc.pairCapacity)));
    uint step = gl_NumWorkGroups.x * RTHDIST_WG;
    for (uint p = gl_GlobalInvocationID.x; p < numPairs; p += step) refinePair(p);
}
