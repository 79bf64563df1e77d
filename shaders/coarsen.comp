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

uint parentKey(uint64_t fine, uint64_t keys, uint c) { return uintAt(keys, cellAt(fine, c).v.first).v >> pc.shift; }

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= pc.numFine) return;
    uint64_t fine = pc.fineCells;
    uint64_t keys = pc.sortedKeys;
    uint key = parentKey(fine, keys, c);
    bool head = c == 0 || parentKey(fine, keys, c - 1) != key;
    if (pc.mode == 0u) {
        uintAt(pc.flags, c).v = head ? 1u : 0u;
        return;
    }
    if (!head) return;
    Cell out_;
    out_.lo = cellAt(fine, c).v.lo;
    out_.hi = cellAt(fine, c).v.hi;
    out_.first = cellAt(fine, c).v.first;
    out_.count = cellAt(fine, c).v.count;
    uint e = c + 1;
    for (; e < pc.numFine && parentKey(fine, keys, e) == key; ++e) {
        out_.lo = min(out_.lo, cellAt(fine, e).v.lo);
        out_.hi = max(out_.hi, cellAt(fine, e).v.hi);
        out_.count += cellAt(fine, e).v.count;
    }
    uint index = uintAt(pc.flags, c).v;
    cellAt(pc.coarseCells, index).v = out_;
    uintAt(pc.fineFirst, index).v = pc.shift == 3u ? c : uintAt(pc.finerFineFirst, c).v;
    if (e == pc.numFine) uintAt(pc.numCoarse, 0).v = index + 1;
}
