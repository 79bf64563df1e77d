#version 460
#extension GL_GOOGLE_include_directive : require
// Exclusive scan of one block of RTHDIST_SCAN_BLOCK uints in place; the
// block's total goes to blockSums (scanned recursively by the host's driver).
// Each thread scans its RTHDIST_SCAN_PER_THREAD consecutive elements serially,
// then the threads' totals are scanned in shared memory (Hillis-Steele).
#include "common.glsl"
layout(local_size_x = RTHDIST_SCAN_WG) in;
layout(push_constant) uniform Push { ScanPush pc; };
shared uint s_sums[RTHDIST_SCAN_WG];

void main() {
    uint t = gl_LocalInvocationID.x;
    uint base = gl_WorkGroupID.x * RTHDIST_SCAN_BLOCK + t * RTHDIST_SCAN_PER_THREAD;
    uint64_t data = pc.data;
    uint local_[RTHDIST_SCAN_PER_THREAD];
    uint sum = 0;
    for (uint i = 0; i < RTHDIST_SCAN_PER_THREAD; ++i) {
        uint idx = base + i;
        uint v = idx < pc.n ? uintAt(data, idx).v : 0u;
        local_[i] = sum;
        sum += v;
    }
    s_sums[t] = sum;
    barrier();
    for (uint d = 1; d < RTHDIST_SCAN_WG; d <<= 1) {
        uint add = t >= d ? s_sums[t - d] : 0u;
        barrier();
        s_sums[t] += add;
        barrier();
    }
    uint offset = s_sums[t] - sum;
    if (t == RTHDIST_SCAN_WG - 1) uintAt(pc.blockSums, gl_WorkGroupID.x).v = s_sums[t];
    for (uint i = 0; i < RTHDIST_SCAN_PER_THREAD; ++i) {
        uint idx = base + i;
        if (idx < pc.n) uintAt(data, idx).v = local_[i] + offset;
    }
}
