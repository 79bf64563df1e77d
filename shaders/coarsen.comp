#version 460
#extension GL_GOOGLE_include_directive : require
// Search cells of level j: runs of level j-1 cells ("fine" here) with the same
// key >> 3j, i.e. cells of edge s * 2^j. They are contiguous in the
// Morton-sorted points, so a search cell is again [first, first + count) with
// the union of the finer tight boxes. The cull keeps the finest cells (few
// points to scan); the BLAS gets cells about half the search radius wide, so
// a ray visits few boxes however large the radius grows.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CoarsenPush pc; };

uint parentKey(CellBuf fine, UintBuf keys, uint c) { return keys.v[fine.v[c].first] >> pc.shift; }

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= pc.numFine) return;
    CellBuf fine = CellBuf(pc.fineCells);
    UintBuf keys = UintBuf(pc.sortedKeys);
    uint key = parentKey(fine, keys, c);
    bool head = c == 0 || parentKey(fine, keys, c - 1) != key;
    if (pc.mode == 0u) {
        UintBuf(pc.flags).v[c] = head ? 1u : 0u;
        return;
    }
    if (!head) return;
    Cell out_;
    out_.lo = fine.v[c].lo;
    out_.hi = fine.v[c].hi;
    out_.first = fine.v[c].first;
    out_.count = fine.v[c].count;
    uint e = c + 1;
    for (; e < pc.numFine && parentKey(fine, keys, e) == key; ++e) {
        out_.lo = min(out_.lo, fine.v[e].lo);
        out_.hi = max(out_.hi, fine.v[e].hi);
        out_.count += fine.v[e].count;
    }
    uint index = UintBuf(pc.flags).v[c];
    CellBuf(pc.coarseCells).v[index] = out_;
    UintBuf(pc.fineFirst).v[index] = pc.shift == 3u ? c : UintBuf(pc.finerFineFirst).v[c];
    if (e == pc.numFine) UintBuf(pc.numCoarse).v[0] = index + 1;
}
