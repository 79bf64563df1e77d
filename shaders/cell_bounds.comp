#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1c, part 3: the tight box of every large cell (more than
// RTHDIST_SERIAL_BOX points), reduced over its points with atomics on
// order-preserving bits; a crowded cell of millions of points costs one pass
// over them in parallel, not one thread's loop.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n || UintRef(pc.largeCells).v == 0u) return;
    uint64_t keys = pc.sortedKeys;
    bool head = i == 0 || uintAt(keys, i - 1).v != uintAt(keys, i).v;
    // flags holds the exclusive scan of the head flags: the cells before i.
    uint cellIndex = uintAt(pc.flags, i).v - (head ? 0u : 1u);
    if (cellAt(pc.cells, cellIndex).v.count <= RTHDIST_SERIAL_BOX) return;
    vec3 p = vec4At(pc.sorted, i).v.xyz;
    for (uint k = 0; k < 3u; ++k) {
        uint bits = orderedBits(p[k]);
        atomicMin(uintAt(pc.boundsU, 6u * cellIndex + k).v, bits);
        atomicMax(uintAt(pc.boundsU, 6u * cellIndex + 3u + k).v, bits);
    }
}
