#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c: run-length encode, part 1: flag the first point of every cell.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    UintBuf keys = UintBuf(pc.sortedKeys);
    UintBuf(pc.flags).v[i] = (i == 0 || keys.v[i] != keys.v[i - 1]) ? 1u : 0u;
}
