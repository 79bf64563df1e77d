#version 460
#extension GL_GOOGLE_include_directive : require
// The number of runs of equal keys (cells) once their head flags are
// scanned (exclusive): the last point's scan plus its own head flag. One
// thread; the host sizes the cells' buffers by it before they are built
// (a leaf split's rounds: leaves hold ~10 points, so a buffer of one Cell
// per point would be ~3x the points' own memory).
#include "common.glsl"
layout(local_size_x = 1) in;
layout(push_constant) uniform Push { CellsPush pc; };

void main() {
    if (pc.n == 0u) {
        uintAt(pc.numCells, 0).v = 0u;
        return;
    }
    uint last = pc.n - 1u;
    uint64_t keys = pc.sortedKeys;
    bool head = last == 0u || uintAt(keys, last).v != uintAt(keys, last - 1u).v;
    uintAt(pc.numCells, 0).v = uintAt(pc.flags, last).v + (head ? 1u : 0u);
}
