#version 460
#extension GL_GOOGLE_include_directive : require
// The bit count's sample of a set ingested on the device (device input):
// every stride-th vec4 record's xyz into a packed float array the host reads
// back, in one dispatch (a copy command with one region per sampled record
// took ~50 ms per set of 32k regions on an H100).
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SampleGatherPush pc; };

void main() {
    uint j = gl_GlobalInvocationID.x;
    if (j >= pc.count) return;
    vec4 p = vec4At(pc.points, j * pc.stride).v;
    floatAt(pc.gathered, 3ul * uint64_t(j)).v = p.x;
    floatAt(pc.gathered, 3ul * uint64_t(j) + 1ul).v = p.y;
    floatAt(pc.gathered, 3ul * uint64_t(j) + 2ul).v = p.z;
}
