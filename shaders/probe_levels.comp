#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_gpu_shader_int64 : require
// The automatic bit count's probe of an ingested set on the device (needs
// shaderFloat64): sampled record j * stride gets the probe key of
// core::chooseBitsFromSample, its cell coordinates (p - origin) * perLength
// in double, clamped to [0, 1023] (the host's operations in the host's order:
// the same keys); then for each level k its top 3k bits go into level k's
// hash table, and a new entry counts one distinct cell of that level. The host
// reads the counts and applies the rule (core::chooseBitsFromCounts).
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { ProbeLevelsPush pc; };

uint probeCoord(float p, uint64_t originBits) {
    precise double c = (double(p) - uint64BitsToDouble(originBits)) * uint64BitsToDouble(pc.perLength);
    if (!(c > 0.0lf)) return 0u;
    if (c >= 1024.0lf) return 1023u;
    return uint(c);
}

void main() {
    uint j = gl_GlobalInvocationID.x;
    if (j >= pc.count) return;
    vec3 p = vec4At(pc.points, j * pc.stride).v.xyz;
    uint key = mortonKey(uvec3(probeCoord(p.x, pc.origin[0]), probeCoord(p.y, pc.origin[1]),
                               probeCoord(p.z, pc.origin[2])));
    const uint slots = 1u << RTHDIST_PROBE_SLOT_BITS;
    for (uint k = 1u; k <= RTHDIST_PROBE_LEVELS; ++k) {
        uint prefix = key >> (3u * (10u - k));
        uint64_t table = pc.tables + uint64_t(k - 1u) * uint64_t(slots) * 4ul;
        uint slot = (prefix * 2654435761u) >> (32u - RTHDIST_PROBE_SLOT_BITS);
        for (uint tries = 0u; tries < slots; ++tries) {
            uint seen = atomicCompSwap(uintAt(table, slot).v, 0u, prefix + 1u);
            if (seen == 0u) {
                atomicAdd(uintAt(pc.counts, k).v, 1u);
                break;
            }
            if (seen == prefix + 1u) break;
            slot = (slot + 1u) & (slots - 1u);
        }
    }
}
