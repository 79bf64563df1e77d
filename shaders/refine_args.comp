#version 460
#extension GL_GOOGLE_include_directive : require
// The refinement's dispatch size, from the pairs the rays appended: the
// search and the refinement of a radius go in one submission (no read-back
// of the pair count between them). refine.comp covers every pair with a
// grid-stride loop, so the group count may be capped at the device's limit.
#include "common.glsl"
layout(local_size_x = 1) in;
layout(push_constant) uniform Push { RefineArgsPush pc; };

void main() {
    uint pairs = uint(min(U64Ref(pc.counters + RTHDIST_CTR_PAIRS).v, uint64_t(pc.pairCapacity)));
    uint groups = min((pairs + RTHDIST_WG - 1u) / RTHDIST_WG, pc.maxGroups);
    uintAt(pc.args, 0u).v = groups;
    uintAt(pc.args, 1u).v = 1u;
    uintAt(pc.args, 2u).v = 1u;
}
