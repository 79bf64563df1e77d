#version 460
#extension GL_GOOGLE_include_directive : require
// Stage 1a: Morton key of each target point's cell; histogram per key.
// With pc.spread (gpu_algo/space_order.hpp), points in spreadItem's order:
// points in space order (a piece's gathered points) send a warp's 32
// atomics to a few lines of the dense table (7.7 ms for 80M points where
// 400M in input order took 5.9 on an H200; spread 2.6 ms), while points in
// no order read in spread order cost more (docs/bench/scale session 20).
// Keys are written by thread, so that the scatter reads them in the same
// order and both write whole lines.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { KeysPush pc; };

void main() {
    uint t = gl_GlobalInvocationID.x;
    uint i = pc.spread != 0u ? spreadItem(t, pc.n) : t;
    if (i >= pc.n) return;
    vec3 p = vec4At(pc.points, i).v.xyz;
    uint key = mortonKey(cellOfClamped(p, pc.grid));
    uintAt(pc.keys, t).v = key;
    atomicAdd(uintAt(pc.dense, key).v, 1u);
}
