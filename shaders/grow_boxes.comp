#version 460
#extension GL_GOOGLE_include_directive : require
// Candidate-search boxes: each cell's tight box grown by the radius plus an
// epsilon, so the traversal never misses a cell within the radius.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { BoxesPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.numCells) return;
    Cell c = CellBuf(pc.cells).v[i];
    AabbBuf a = AabbBuf(pc.aabbs);
    vec3 lo = c.lo - vec3(pc.grow), hi = c.hi + vec3(pc.grow);
    a.v[6 * i + 0] = lo.x;
    a.v[6 * i + 1] = lo.y;
    a.v[6 * i + 2] = lo.z;
    a.v[6 * i + 3] = hi.x;
    a.v[6 * i + 4] = hi.y;
    a.v[6 * i + 5] = hi.z;
}
