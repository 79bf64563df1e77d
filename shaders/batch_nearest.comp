#version 460
#extension GL_GOOGLE_include_directive : require
// The small-pair batch (computeBatch on a GPU backend): every query of a
// chunk scans the targets of its direction exactly, RTHDIST_WG at a time
// through shared memory, in the order (j * step) mod n, which spreads the
// first targets over the whole set (cell order is spatial) so that a query
// finds a target as near as the running maximum early. Exact: a query stops
// only with a target at most as far as the maximum, which a finished query
// (its witness, whose nearest target is written) has as its exact nearest
// distance, so it cannot raise h (design.md §3); a query that finishes has its
// exact nearest distance (ties: the smallest input index).
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { BatchNearestPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) buffer DirectionRef { BatchDirection v; };

shared vec4 tile[RTHDIST_WG];
shared uint anyAlive;
shared float threshold;

void main() {
    const uint lid = gl_LocalInvocationID.x;
    const uvec2 chunk = uvec2At(pc.chunks, gl_WorkGroupID.x).v;
    const BatchDirection d =
        DirectionRef(pc.directions + uint64_t(chunk.x) * uint64_t(RTHDIST_BATCH_DIRECTION_BYTES)).v;
    const uint64_t maxAddr = pc.maxPacked + uint64_t(chunk.x) * 8ul;
    const uint qpos = pc.seed != 0u ? lid * d.sampleStride : chunk.y + lid;
    const bool valid = qpos < d.queryCount;
    vec3 q = vec3(0.0);
    uint qIndex = 0u;
    if (valid) {
        const vec4 r = vec4At(d.queries, qpos).v;
        q = r.xyz * d.queryScale;
        qIndex = floatBitsToUint(r.w);
    }
    float best = uintBitsToFloat(0x7f800000u);  // +inf
    uint bestIndex = 0xffffffffu;
    bool alive = valid;
    const uint n = d.targetCount;
    for (uint base = 0u; base < n; base += RTHDIST_WG) {
        const uint j = base + lid;
        if (j < n) {
            const uint t = uint((uint64_t(j) * uint64_t(d.step)) % uint64_t(n));
            const vec4 r = vec4At(d.targets, t).v;
            tile[lid] = vec4(r.xyz * d.targetScale, r.w);
        }
        barrier();
        const uint count = min(uint(RTHDIST_WG), n - base);
        if (alive) {
            for (uint k = 0u; k < count; ++k) {
                const vec4 t = tile[k];
                const float d2 = dist2(q, t.xyz);
                const uint ti = floatBitsToUint(t.w);
                if (d2 < best || (d2 == best && ti < bestIndex)) {
                    best = d2;
                    bestIndex = ti;
                }
            }
        }
        if (lid == 0u) {
            anyAlive = 0u;
            // An atomic read of the running maximum (other workgroups raise it).
            threshold = pc.earlyBreak != 0u ? packedDist2(atomicOr(u64At(maxAddr, 0u).v, 0ul)) : -1.0;
        }
        barrier();
        if (alive && best <= threshold) {
            alive = false;
            // The killing target: a real one within the maximum (the certificate's band).
            uintAt(d.nearest, qIndex).v = bestIndex;
        }
        if (alive) anyAlive = 1u;
        barrier();
        if (anyAlive == 0u) break;
    }
    if (!alive) return;
    raiseMax(maxAddr, packDistIndex(best, qIndex));
    uintAt(d.nearest, qIndex).v = bestIndex;
}
