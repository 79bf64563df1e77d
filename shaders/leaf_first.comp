#version 460
#extension GL_GOOGLE_include_directive : require
// After the leaf split: the first leaf of every grid cell (leaves are runs of
// the cell-sorted points, a cell's leaves contiguous), so the neighbourhood
// pass finds a crowded cell's leaves in O(1) and scans those near its query.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { LeafFirstPush pc; };

void main() {
    uint l = gl_GlobalInvocationID.x;
    if (l >= pc.numLeaves) return;
    uint key = uintAt(pc.sortedKeys, cellAt(pc.leaves, l).v.first).v;
    if (l > 0u && uintAt(pc.sortedKeys, cellAt(pc.leaves, l - 1u).v.first).v == key) return;
    uintAt(pc.leafFirst, key).v = l;
}
