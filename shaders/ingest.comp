#version 460
#extension GL_GOOGLE_include_directive : require
// The data path's first stage: the caller's points (three floats every
// `stride` bytes) into the vec4 records the index build reads, in one pass
// that also reduces their bounds (per workgroup in shared memory, then one
// atomic per axis and workgroup) and finds the first point that is not
// finite. The host makes no pass over the points besides the copy into a
// buffer the device can read.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { IngestPush pc; };

shared uint s_lo[3];
shared uint s_hi[3];

// Exponent all ones: infinite or NaN (a bit test: no reliance on isnan,
// which a compiler may fold away).
bool finiteBits(float f) { return (floatBitsToUint(f) & 0x7f800000u) != 0x7f800000u; }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (gl_LocalInvocationID.x < 3u) {
        s_lo[gl_LocalInvocationID.x] = 0xffffffffu;
        s_hi[gl_LocalInvocationID.x] = 0u;
    }
    barrier();
    if (i < pc.n) {
        uint64_t at = pc.source + uint64_t(i) * uint64_t(pc.stride);
        vec3 p = vec3(FloatRef(at).v, FloatRef(at + 4ul).v, FloatRef(at + 8ul).v);
        vec4At(pc.points, i).v = vec4(p, 0.0);
        if (finiteBits(p.x) && finiteBits(p.y) && finiteBits(p.z)) {
            for (uint k = 0u; k < 3u; ++k) {
                atomicMin(s_lo[k], orderedBits(p[k]));
                atomicMax(s_hi[k], orderedBits(p[k]));
            }
        } else {
            atomicMin(UintRef(pc.summary + 24ul).v, i);
        }
    }
    barrier();
    if (gl_LocalInvocationID.x < 3u && s_lo[gl_LocalInvocationID.x] != 0xffffffffu) {
        uint k = gl_LocalInvocationID.x;
        atomicMin(UintRef(pc.summary + 4ul * k).v, s_lo[k]);
        atomicMax(UintRef(pc.summary + 12ul + 4ul * k).v, s_hi[k]);
    }
}
