#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c, part 2: one Cell per run (flags scanned into cell indices), with
// the tight box of its points; the first point is the representative.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    UintBuf keys = UintBuf(pc.sortedKeys);
    uint key = keys.v[i];
    if (i != 0 && keys.v[i - 1] == key) return;
    uint cellIndex = UintBuf(pc.flags).v[i];
    uint end = UintBuf(pc.dense).v[key];
    Vec4Buf pts = Vec4Buf(pc.sorted);
    vec3 lo = pts.v[i].xyz, hi = lo;
    for (uint j = i + 1; j < end; ++j) {
        vec3 p = pts.v[j].xyz;
        lo = min(lo, p);
        hi = max(hi, p);
    }
    Cell c;
    c.lo = lo;
    c.hi = hi;
    c.first = i;
    c.count = end - i;
    CellBuf(pc.cells).v[cellIndex] = c;
    if (end == pc.n) UintBuf(pc.numCells).v[0] = cellIndex + 1;
}
