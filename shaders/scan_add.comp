#version 460
#extension GL_GOOGLE_include_directive : require
// Adds each block's scanned offset to its elements (second half of the scan).
#include "common.glsl"
layout(local_size_x = RTHDIST_SCAN_WG) in;
layout(push_constant) uniform Push { ScanPush pc; };

void main() {
    uint block = gl_WorkGroupID.x;
    uint add = uintAt(pc.blockSums, block).v;
    uint base = block * RTHDIST_SCAN_BLOCK;
    uint64_t data = pc.data;
    for (uint j = gl_LocalInvocationID.x; j < RTHDIST_SCAN_BLOCK; j += RTHDIST_SCAN_WG) {
        uint i = base + j;
        if (i < pc.n) uintAt(data, i).v += add;
    }
}
