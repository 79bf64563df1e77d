#version 460
#extension GL_GOOGLE_include_directive : require
// The certificate's brute force (core/certificate.hpp): every target of the
// direction against up to RTHDIST_CERT_ENTRIES band queries. Mode 0 appends
// every target within an entry's squared bound as a candidate, which the host
// settles in double; mode 1 finds each entry's float nearest target (its
// bound for a second mode-0 pass when the first one's candidates overflowed).
// One read of the targets, whatever the number of queries; a grid-stride loop.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CertScanPush pc; };

shared vec4 entries[RTHDIST_CERT_ENTRIES];

void main() {
    const uint count = min(pc.entryCount, uint(RTHDIST_CERT_ENTRIES));
    for (uint k = gl_LocalInvocationID.x; k < count; k += RTHDIST_WG) entries[k] = vec4At(pc.entries, k).v;
    barrier();
    const uint step = gl_NumWorkGroups.x * RTHDIST_WG;
    for (uint t = gl_GlobalInvocationID.x; t < pc.n; t += step) {
        const vec4 p = vec4At(pc.targets, t).v;
        for (uint k = 0u; k < count; ++k) {
            const float d2 = dist2(entries[k].xyz, p.xyz);
            if (pc.mode == 1u) {
                const uint64_t packed = packDistIndex(d2, floatBitsToUint(p.w));
                if (packed < u64At(pc.found, k).v) atomicMin(u64At(pc.found, k).v, packed);
            } else if (d2 <= entries[k].w) {
                const uint j = atomicAdd(UintRef(pc.found).v, 1u);
                if (j < pc.capacity) uvec2At(pc.found + 8ul, j).v = uvec2(k, floatBitsToUint(p.w));
            }
        }
    }
}
