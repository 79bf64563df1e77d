#version 460
#extension GL_GOOGLE_include_directive : require
// Leaf splitting, step 1: slots per cell. A cell of more than leafMax points
// whose tight box is not a single point gets 8^k slots (its box cut into 2^k
// parts per axis, 8^k <= count, so all slots together stay below cells + n);
// every other cell keeps one. The narrowest sub-cell edge goes to minEdge
// (the first search radius of a split index).
#include "common.glsl"
#include "leaf_split.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SplitPush pc; };

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= pc.numCells) return;
    Cell cell = cellAt(pc.cells, c).v;
    uint k = splitBits(cell, pc.leafMax);
    uintAt(pc.slotBase, c).v = 1u << (3u * k);
    if (k > 0u) {
        vec3 ext = cell.hi - cell.lo;
        float edge = max(max(ext.x, ext.y), ext.z) / float(1u << k);
        if (edge > 0.0) atomicMin(UintRef(pc.minEdge).v, floatBitsToUint(edge));
    }
}
