#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c: run-length encode, part 1: flag the first point of every cell.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    uint64_t keys = pc.sortedKeys;
    uintAt(pc.flags, i).v = (i == 0 || uintAt(keys, i).v != uintAt(keys, i - 1).v) ? 1u : 0u;
}
