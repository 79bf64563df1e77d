#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c, part 4: large cells take their reduced box (cell_bounds.comp),
// and the largest count of a cell that can split goes to maxCount.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= pc.cellCapacity || UintRef(pc.largeCells).v == 0u || c >= uintAt(pc.numCells, 0).v) return;
    uint count = cellAt(pc.cells, c).v.count;
    if (count <= RTHDIST_SERIAL_BOX) return;
    vec3 lo, hi;
    for (uint k = 0; k < 3u; ++k) {
        lo[k] = fromOrderedBits(uintAt(pc.boundsU, 6u * c + k).v);
        hi[k] = fromOrderedBits(uintAt(pc.boundsU, 6u * c + 3u + k).v);
    }
    cellAt(pc.cells, c).v.lo = lo;
    cellAt(pc.cells, c).v.hi = hi;
    if (any(notEqual(lo, hi))) {
        atomicMax(UintRef(pc.maxCount).v, count);
        return;
    }
    // Copies of one position, scanned through their first point alone: the
    // copy of the smallest original index goes first (the tie rule; one
    // thread per such cell, a rare case: many exact copies of one point).
    uint first = cellAt(pc.cells, c).v.first, smallest = first;
    for (uint j = first + 1u; j < first + count; ++j)
        if (floatBitsToUint(vec4At(pc.sorted, j).v.w) < floatBitsToUint(vec4At(pc.sorted, smallest).v.w)) smallest = j;
    if (smallest != first) {
        vec4 head = vec4At(pc.sorted, first).v;
        vec4At(pc.sorted, first).v = vec4At(pc.sorted, smallest).v;
        vec4At(pc.sorted, smallest).v = head;
    }
}
