#version 460
#extension GL_GOOGLE_include_directive : require
// The small-pair batch's witnesses: per direction, the query that set the
// maximum (batch_nearest.comp), its nearest target and the maximum's bits,
// for the host to read back in one buffer.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { BatchWitnessPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) buffer DirectionRef { BatchDirection v; };

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    const uint64_t packed = u64At(pc.maxPacked, i).v;
    const uint64_t nearest =
        DirectionRef(pc.directions + uint64_t(i) * uint64_t(RTHDIST_BATCH_DIRECTION_BYTES)).v.nearest;
    const uint qIndex = uint(packed & 0xfffffffful);
    uintAt(pc.witnesses, 4u * i).v = qIndex;
    uintAt(pc.witnesses, 4u * i + 1u).v = uintAt(nearest, qIndex).v;
    uintAt(pc.witnesses, 4u * i + 2u).v = uint(packed >> 32);
    uintAt(pc.witnesses, 4u * i + 3u).v = 0u;
}
