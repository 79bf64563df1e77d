#version 460
#extension GL_GOOGLE_include_directive : require
// The candidate search's far tail (CandidateSearch::tailScanLevel): each
// query still open scans every search cell of one level, without rays. One
// thread per query; the cells pass through shared memory, RTHDIST_WG at a
// time. A cell whose box is farther than the best distance known for the
// query (earlier pairs, the neighbourhood pass, this scan) is skipped, else
// its level-0 cells are scanned as refine.comp scans a pair's
// (scan_cells.glsl). Every target lies in one of the cells, so the scan is
// complete and resolve.comp then settles each query at radius +inf; a query
// that lost pairs to a full buffer (RETRY) is open again, as nothing was
// dropped here.
#include "common.glsl"
#include "scan_cells.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { TailScanPush pc; };

shared Cell tile[RTHDIST_WG];
shared uvec2 tileFine[RTHDIST_WG];  // each tile cell's level-0 cells [first, end)

void main() {
    const uint lid = gl_LocalInvocationID.x;
    const uint slot = gl_GlobalInvocationID.x;
    const uint64_t state = pc.state;
    bool open = slot < pc.numActive;
    uint qi = 0u;
    vec3 q = vec3(0.0);
    float bound = 0.0;
    if (open) {
        qi = uintAt(pc.activeList, slot).v;
        const QueryState st = stateAt(state, qi).v;
        open = st.status != RTHDIST_DEAD;
        if (st.status == RTHDIST_RETRY) stateAt(state, qi).v.status = RTHDIST_OPEN;
        q = vec4At(pc.queries, qi).v.xyz;
        bound = packedDist2(st.best);
    }
    const float thr = deadThreshold(pc.maxPacked, pc.lowerBound2);
    const bool coarse = pc.fineFirst != 0ul;
    const uint n = pc.numSearchCells;
    float best = uintBitsToFloat(0x7f800000u);
    uint bestT = 0u;
    bool dead = false;
    for (uint base = 0u; base < n; base += RTHDIST_WG) {
        const uint j = base + lid;
        if (j < n) {
            tile[lid] = cellAt(pc.cells, j).v;
            if (coarse)
                tileFine[lid] =
                    uvec2(uintAt(pc.fineFirst, j).v, j + 1u < n ? uintAt(pc.fineFirst, j + 1u).v : pc.numFineCells);
        }
        barrier();
        const uint count = min(uint(RTHDIST_WG), n - base);
        for (uint k = 0u; k < count && open && !dead && best > 0.0; ++k) {
            const Cell c = tile[k];
            if (boxDist2(q, c.lo, c.hi) > min(bound, best)) continue;
            if (coarse)
                scanFineCells(q, tileFine[k].x, tileFine[k].y, bound, thr, pc.fineCells, pc.targets, best, bestT,
                              dead);
            else
                scanCellPoints(q, c, pc.targets, thr, best, bestT, dead);
        }
        barrier();
    }
    if (!open || best == uintBitsToFloat(0x7f800000u)) return;
    atomicMin(stateAt(state, qi).v.best, packDistIndex(best, bestT));
}
