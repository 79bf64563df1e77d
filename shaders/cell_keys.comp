#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1a: Morton key of each target point's cell; histogram per key.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { KeysPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    vec3 p = vec4At(pc.points, i).v.xyz;
    uint key = mortonKey(cellOfClamped(p, pc.grid));
    uintAt(pc.keys, i).v = key;
    atomicAdd(uintAt(pc.dense, key).v, 1u);
}
