#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1b: counting-sort scatter into cell order (order inside a cell is
// irrelevant). Afterwards dense[key] holds the end of the key's cell.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { ScatterPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n) return;
    uint key = UintBuf(pc.keys).v[i];
    uint pos = atomicAdd(UintBuf(pc.dense).v[key], 1u);
    vec3 p = Vec4Buf(pc.points).v[i].xyz;
    Vec4Buf(pc.sorted).v[pos] = vec4(p, uintBitsToFloat(i));
    UintBuf(pc.sortedKeys).v[pos] = key;
}
