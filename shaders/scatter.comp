#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1b: counting-sort scatter into cell order (order inside a cell is
// irrelevant). Afterwards dense[key] holds the end of the key's cell.
// Points in the order cell_keys.comp took them (pc.spread), keys by thread.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { ScatterPush pc; };

void main() {
    uint t = gl_GlobalInvocationID.x;
    uint i = pc.spread != 0u ? spreadItem(t, pc.n) : t;
    if (i >= pc.n) return;
    uint key = uintAt(pc.keys, t).v;
    uint pos = atomicAdd(uintAt(pc.dense, key).v, 1u);
    vec3 p = vec4At(pc.points, i).v.xyz;
    vec4At(pc.sorted, pos).v = vec4(p, uintBitsToFloat(i));
    uintAt(pc.sortedKeys, pos).v = key;
}
