#version 460
#extension GL_GOOGLE_include_directive : require
// Self-check of one index (costs one read of the sorted points): every sorted
// record must sit under its own cell key, keys must not decrease, and the
// original indices must be a permutation of 0..n-1 (their sum is compared with
// n(n-1)/2 on the host). A record written at a wrapped offset, a lost or a
// duplicated point breaks one of the three.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CheckPush pc; };
shared uint64_t s_sum[RTHDIST_WG];

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint t = gl_LocalInvocationID.x;
    uint64_t index = 0;
    if (i < pc.n) {
        vec4 p = vec4At(pc.sorted, i).v;
        uint key = uintAt(pc.sortedKeys, i).v;
        index = uint64_t(floatBitsToUint(p.w));
        bool bad = key != mortonKey(cellOfClamped(p.xyz, pc.grid)) || index >= uint64_t(pc.n) ||
                   (i > 0 && uintAt(pc.sortedKeys, i - 1).v > key);
        if (bad) atomicAdd(U64Ref(pc.counters + RTHDIST_CTR_CHECK_BAD).v, 1ul);
    }
    s_sum[t] = index;
    barrier();
    for (uint d = RTHDIST_WG / 2; d > 0; d >>= 1) {
        if (t < d) s_sum[t] += s_sum[t + d];
        barrier();
    }
    if (t == 0) atomicAdd(U64Ref(pc.counters + RTHDIST_CTR_CHECK_SUM).v, s_sum[0]);
}
