#version 460
#extension GL_GOOGLE_include_directive : require
// The candidate search's far tail (CandidateSearch::tailScanLevel): each
// query still open scans every search cell of one level, without rays.
// One workgroup per query, its threads taking the cells in turn:
//   1. each thread bounds the nearest distance by the nearest far corner of
//      its cells' boxes (a box holds a point within its far corner:
//      scan_cells.glsl) and notes its nearest box; the group keeps the
//      smallest bound;
//   2. each thread whose nearest box is within the bound scans that cell
//      first, so the group's running best starts near the nearest distance;
//   3. each thread scans its other cells, skipping one whose box is farther
//      than the bound, the group's running best or the best distance known
//      for the query before (earlier pairs, the neighbourhood pass); a cell
//      is scanned through its level-0 cells as refine.comp scans a pair's.
// Every target lies in one of the cells, so the scan is complete: each
// thread's best goes into the query's state (atomicMin: the smallest
// distance, then the smallest index), and resolve.comp then settles every
// query at radius +inf. A query that lost pairs to a full buffer (RETRY) is
// open again, as nothing was dropped here.
// Measured on an H100, 15k isolated voxels of a noisy mask over 1,960
// cells: one thread per query took 4.2 ms in cell order and 2.3-2.5 ms with
// steps 1-2 (each thread waited on its own descents, one after another).
#include "common.glsl"
#include "scan_cells.glsl"
layout(local_size_x = RTHDIST_TAIL_WG) in;
layout(push_constant) uniform Push { TailScanPush pc; };

shared uint groupBound;  // float bits (non-negative floats order as their bits)
shared uint groupBest;
shared bool groupOpen;

#define kInf uintBitsToFloat(0x7f800000u)

// The level-0 cells of search cell j (itself at level 0).
void scanSearchCell(vec3 q, uint j, float bound, float thr, inout float best, inout uint bestT, inout bool dead) {
    const uint n = pc.numSearchCells;
    if (pc.fineFirst == 0ul) {
        scanCellPoints(q, cellAt(pc.cells, j).v, pc.targets, thr, best, bestT, dead);
        return;
    }
    const uint f0 = uintAt(pc.fineFirst, j).v;
    const uint f1 = j + 1u < n ? uintAt(pc.fineFirst, j + 1u).v : pc.numFineCells;
    scanFineCells(q, f0, f1, bound, thr, pc.fineCells, pc.targets, best, bestT, dead);
}

void main() {
    const uint lid = gl_LocalInvocationID.x;
    const uint slot = gl_WorkGroupID.x;
    const uint64_t state = pc.state;
    const uint qi = uintAt(pc.activeList, slot).v;
    const QueryState st = stateAt(state, qi).v;
    if (lid == 0u) {
        groupBound = floatBitsToUint(packedDist2(st.best));
        groupBest = floatBitsToUint(kInf);
        groupOpen = st.status != RTHDIST_DEAD;
        if (st.status == RTHDIST_RETRY) stateAt(state, qi).v.status = RTHDIST_OPEN;
    }
    barrier();
    if (!groupOpen) return;  // uniform: every thread read it after the barrier
    const vec3 q = vec4At(pc.queries, qi).v.xyz;
    const float thr = deadThreshold(pc.maxPacked, pc.lowerBound2);
    const uint n = pc.numSearchCells;

    // 1. The bound and each thread's nearest box.
    float far = kInf, nearestBox = kInf;
    uint nearestCell = 0xffffffffu;
    for (uint j = lid; j < n; j += RTHDIST_TAIL_WG) {
        const Cell c = cellAt(pc.cells, j).v;
        far = min(far, boxFarDist2(q, c.lo, c.hi));
        const float near = boxDist2(q, c.lo, c.hi);
        if (near < nearestBox) {
            nearestBox = near;
            nearestCell = j;
        }
    }
    atomicMin(groupBound, floatBitsToUint(far));
    barrier();

    // 2. The nearest boxes first.
    float best = kInf;
    uint bestT = 0u;
    bool dead = false;
    float bound = uintBitsToFloat(groupBound);
    if (nearestBox <= bound) {
        scanSearchCell(q, nearestCell, bound, thr, best, bestT, dead);
        atomicMin(groupBest, floatBitsToUint(best));
    }
    barrier();

    // 3. The other cells, against the group's running best.
    for (uint j = lid; j < n && !dead && best > 0.0; j += RTHDIST_TAIL_WG) {
        if (j == nearestCell) continue;
        const Cell c = cellAt(pc.cells, j).v;
        const float limit = min(min(bound, best), uintBitsToFloat(groupBest));
        if (boxDist2(q, c.lo, c.hi) > limit) continue;
        scanSearchCell(q, j, limit, thr, best, bestT, dead);
        atomicMin(groupBest, floatBitsToUint(best));
    }
    if (best == kInf) return;
    atomicMin(stateAt(state, qi).v.best, packDistIndex(best, bestT));
}
