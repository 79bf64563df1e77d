#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 3: exact minimum over the points of each candidate (query, search
// cell) pair (scan_cells.glsl), breaking off once a point is strictly closer
// than the running maximum. One thread per pair (grid-stride).
#include "common.glsl"
#include "scan_cells.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { RefinePush pc; };

void refinePair(uint p) {
    if (pc.mutant != 0u && p % 3u == 0u) return;  // tests only: a search that misses candidates
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
    float best = uintBitsToFloat(0x7f800000u);
    uint bestT = 0;
    bool dead = false;
    scanFineCells(q, f0, f1, bound, thr, pc.fineCells, pc.targets, best, bestT, dead);
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
