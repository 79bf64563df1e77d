#version 460
#extension GL_GOOGLE_include_directive : require
// Candidate-search boxes: each cell's tight box grown by the radius plus an
// epsilon, so the traversal never misses a cell within the radius. The
// epsilon covers float rounding at the box's own magnitude (a few ulps of its
// largest coordinate plus the radius) and the grid's absolute rounding.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { BoxesPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.numCells) return;
    Cell c = cellAt(pc.cells, i).v;
    uint64_t a = pc.aabbs;
    vec3 mag = max(abs(c.lo), abs(c.hi));
    float grow = pc.grow + pc.absEps + pc.relEps * (max(max(mag.x, mag.y), mag.z) + pc.grow);
    vec3 lo = c.lo - vec3(grow), hi = c.hi + vec3(grow);
    floatAt(a, 6ul * i + 0ul).v = lo.x;
    floatAt(a, 6ul * i + 1ul).v = lo.y;
    floatAt(a, 6ul * i + 2ul).v = lo.z;
    floatAt(a, 6ul * i + 3ul).v = hi.x;
    floatAt(a, 6ul * i + 4ul).v = hi.y;
    floatAt(a, 6ul * i + 5ul).v = hi.z;
}
