#version 460
#extension GL_GOOGLE_include_directive : require
// Leaf splitting, step 2: the slot of every sorted point (its cell's first
// slot plus its sub-cell's Morton key), counted into the slot histogram.
#include "common.glsl"
#include "leaf_split.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SplitPush pc; };

// The cell holding sorted position i: the last cell whose first is <= i.
uint cellOf(uint i) {
    uint lo = 0u, hi = pc.numCells - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1;
        if (cellAt(pc.cells, mid).v.first <= i) lo = mid;
        else hi = mid - 1u;
    }
    return lo;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    uint c = cellOf(i);
    Cell cell = cellAt(pc.cells, c).v;
    uint k = splitBits(cell, pc.leafMax);
    uint slot = uintAt(pc.slotBase, c).v;
    if (k > 0u) slot += subCellKey(vec4At(pc.sorted, i).v.xyz, cell, k);
    uintAt(pc.slotKeys, i).v = slot;
    atomicAdd(uintAt(pc.dense, slot).v, 1u);
}
