#version 460
#extension GL_GOOGLE_include_directive : require
// Exclusive scan of one block of RTHDIST_SCAN_BLOCK uints in place; the
// block's total goes to blockSums (scanned recursively by the host's driver).
#include "common.glsl"
layout(local_size_x = RTHDIST_SCAN_WG) in;
layout(push_constant) uniform Push { ScanPush pc; };
shared uint s_data[RTHDIST_SCAN_BLOCK];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint base = gl_WorkGroupID.x * RTHDIST_SCAN_BLOCK;
    UintBuf data = UintBuf(pc.data);
    uint i0 = base + 2 * t, i1 = base + 2 * t + 1;
    s_data[2 * t] = i0 < pc.n ? data.v[i0] : 0u;
    s_data[2 * t + 1] = i1 < pc.n ? data.v[i1] : 0u;
    // Blelloch up-sweep.
    uint offset = 1;
    for (uint d = RTHDIST_SCAN_BLOCK >> 1; d > 0; d >>= 1) {
        barrier();
        if (t < d) {
            uint ai = offset * (2 * t + 1) - 1, bi = offset * (2 * t + 2) - 1;
            s_data[bi] += s_data[ai];
        }
        offset <<= 1;
    }
    barrier();
    if (t == 0) {
        UintBuf(pc.blockSums).v[gl_WorkGroupID.x] = s_data[RTHDIST_SCAN_BLOCK - 1];
        s_data[RTHDIST_SCAN_BLOCK - 1] = 0u;
    }
    // Down-sweep.
    for (uint d = 1; d < RTHDIST_SCAN_BLOCK; d <<= 1) {
        offset >>= 1;
        barrier();
        if (t < d) {
            uint ai = offset * (2 * t + 1) - 1, bi = offset * (2 * t + 2) - 1;
            uint x = s_data[ai];
            s_data[ai] = s_data[bi];
            s_data[bi] += x;
        }
    }
    barrier();
    if (i0 < pc.n) data.v[i0] = s_data[2 * t];
    if (i1 < pc.n) data.v[i1] = s_data[2 * t + 1];
}
