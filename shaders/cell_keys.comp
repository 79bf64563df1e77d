#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1a: Morton key of each target point's cell; histogram per key.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { KeysPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    vec3 p = Vec4Buf(pc.points).v[i].xyz;
    uint key = mortonKey(cellOfClamped(p, pc.grid));
    UintBuf(pc.keys).v[i] = key;
    atomicAdd(UintBuf(pc.dense).v[key], 1u);
}
