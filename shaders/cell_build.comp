#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c, part 2: one Cell per run (flags scanned into cell indices), with
// the tight box of its points; the first point is the representative. The
// largest count of a cell that can split (not all one point) goes to maxCount.
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
    uint64_t pts = pc.sorted;
    vec3 lo = vec4At(pts, i).v.xyz, hi = lo;
    for (uint j = i + 1; j < end; ++j) {
        vec3 p = vec4At(pts, j).v.xyz;
        lo = min(lo, p);
        hi = max(hi, p);
    }
    Cell c;
    c.lo = lo;
    c.hi = hi;
    c.first = i;
    c.count = end - i;
    cellAt(pc.cells, cellIndex).v = c;
    if (any(notEqual(lo, hi))) atomicMax(UintRef(pc.maxCount).v, c.count);
    if (end == pc.n) uintAt(pc.numCells, 0).v = cellIndex + 1;
}
