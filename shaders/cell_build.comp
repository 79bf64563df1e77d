#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c, part 2: one Cell per run (flags scanned into cell indices), with
// the tight box of its points; the first point is the representative. The
// largest count of a cell that can split (not all one point) goes to maxCount.
// A cell of more than RTHDIST_SERIAL_BOX points only gets its box's start
// values here (cell_bounds.comp reduces it in parallel).
// A cell of copies of one position is scanned through its first point alone
// (scan_cells.glsl, cull.comp): that first point is made the copy of the
// smallest original index (the tie rule), whatever order the sort left.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    uint64_t keys = pc.sortedKeys;
    uint key = uintAt(keys, i).v;
    if (i != 0 && uintAt(keys, i - 1).v == key) return;
    uint cellIndex = uintAt(pc.flags, i).v;
    uint end = uintAt(pc.dense, key).v;
    Cell c;
    c.first = i;
    c.count = end - i;
    if (c.count > RTHDIST_SERIAL_BOX) {
        // Large cell: its box is reduced over all its points in parallel.
        for (uint k = 0; k < 3u; ++k) {
            uintAt(pc.boundsU, 6u * cellIndex + k).v = 0xffffffffu;
            uintAt(pc.boundsU, 6u * cellIndex + 3u + k).v = 0u;
        }
        c.lo = vec3(0.0);
        c.hi = vec3(0.0);
        cellAt(pc.cells, cellIndex).v = c;
        UintRef(pc.largeCells).v = 1u;
        if (end == pc.n) uintAt(pc.numCells, 0).v = cellIndex + 1;
        return;
    }
    uint64_t pts = pc.sorted;
    vec3 lo = vec4At(pts, i).v.xyz, hi = lo;
    uint smallest = i;  // the point of the smallest original index
    for (uint j = i + 1; j < end; ++j) {
        vec4 p = vec4At(pts, j).v;
        lo = min(lo, p.xyz);
        hi = max(hi, p.xyz);
        if (floatBitsToUint(p.w) < floatBitsToUint(vec4At(pts, smallest).v.w)) smallest = j;
    }
    if (all(equal(lo, hi)) && smallest != i) {  // copies: the smallest index first
        vec4 first = vec4At(pts, i).v;
        vec4At(pts, i).v = vec4At(pts, smallest).v;
        vec4At(pts, smallest).v = first;
    }
    c.lo = lo;
    c.hi = hi;
    cellAt(pc.cells, cellIndex).v = c;
    if (c.count > RTHDIST_LEAF_MAX && any(notEqual(lo, hi))) atomicMax(UintRef(pc.maxCount).v, c.count);
    if (end == pc.n) uintAt(pc.numCells, 0).v = cellIndex + 1;
}
