#version 460
#extension GL_GOOGLE_include_directive : require
// Leaf splitting, step 3: counting-sort scatter by slot. A cell's slots are
// consecutive and in cell order, so every point stays inside its cell's range
// [first, first + count) and the grid cells stay contiguous runs (the dense
// grid table remains valid). Afterwards dense[slot] holds the slot's end.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SplitPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    uint slot = uintAt(pc.slotKeys, i).v;
    uint pos = atomicAdd(uintAt(pc.dense, slot).v, 1u);
    vec4At(pc.outSorted, pos).v = vec4At(pc.sorted, i).v;
    uintAt(pc.outGridKeys, pos).v = uintAt(pc.gridKeys, i).v;
    uintAt(pc.outSlotKeys, pos).v = slot;
}
