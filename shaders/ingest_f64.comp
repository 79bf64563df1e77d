#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_gpu_shader_int64 : require
// Device input (include/rthdist/vulkan_interop.hpp): the embedder's points,
// three floats or doubles every `stride` bytes of its own buffer, read in
// double. Mode 0 reduces the view's box in double (per workgroup in shared
// memory, then one 64-bit atomic per axis and workgroup on order-preserving
// bits), finds its first non-finite point and whether any coordinate is not
// a float32 value: what the host path's summarizeSet finds (core/input_frame).
// Mode 1 writes float(p - origin), the difference taken in double and rounded
// to nearest (the host path's roundedCopy), into the vec4 records of the
// index build, with their float bounds as ingest.comp reduces them. Needs
// shaderFloat64; the other shaders do not.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { IngestDevicePush pc; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer DoubleRef { double v; };

shared double s_lo[3][RTHDIST_WG];
shared double s_hi[3][RTHDIST_WG];
shared uint s_flo[3];
shared uint s_fhi[3];

const uint64_t kExpMask = 0x7ff0000000000000ul;
const uint64_t kSign = 0x8000000000000000ul;

bool finite64(double d) { return (doubleBitsToUint64(d) & kExpMask) != kExpMask; }
uint64_t orderedBits64(double d) {
    uint64_t b = doubleBitsToUint64(d);
    return (b & kSign) != 0ul ? ~b : b | kSign;
}

// Whether d is a float32 value, from its bits (double(float(d)) == d may be
// folded to true by a compiler): zero, or a normal float's exponent with the
// low 29 mantissa bits clear, or a subnormal float's value (a multiple of 2^-149).
bool floatValue(double d) {
    uint64_t b = doubleBitsToUint64(d) & ~kSign;
    if (b == 0ul) return true;
    int e = int(b >> 52) - 1023;
    uint64_t mantissa = b & 0xffffffffffffful;
    if (e > 127 || e < -149) return false;
    int dropped = e >= -126 ? 29 : 29 + (-126 - e);  // mantissa bits a float cannot hold
    return (mantissa & ((1ul << uint(dropped)) - 1ul)) == 0ul;
}

dvec3 readPoint(uint i) {
    uint64_t at = pc.source + uint64_t(i) * uint64_t(pc.stride);
    if (pc.isDouble != 0u) return dvec3(DoubleRef(at).v, DoubleRef(at + 8ul).v, DoubleRef(at + 16ul).v);
    return dvec3(FloatRef(at).v, FloatRef(at + 4ul).v, FloatRef(at + 8ul).v);
}

// Mode 0: box, first bad point, float-exactness.
void summarize(uint i, uint t) {
    const double inf = uint64BitsToDouble(kExpMask);
    dvec3 lo = dvec3(inf), hi = dvec3(-inf);
    if (i < pc.n) {
        dvec3 p = readPoint(i);
        if (finite64(p.x) && finite64(p.y) && finite64(p.z)) {
            lo = p;
            hi = p;
            if (!floatValue(p.x) || !floatValue(p.y) || !floatValue(p.z))
                atomicOr(UintRef(pc.summary + 52ul).v, 1u);
        } else {
            atomicMin(UintRef(pc.summary + 48ul).v, i);
        }
    }
    for (uint k = 0u; k < 3u; ++k) {
        s_lo[k][t] = lo[k];
        s_hi[k][t] = hi[k];
    }
    barrier();
    for (uint s = RTHDIST_WG / 2u; s > 0u; s >>= 1u) {
        if (t < s) {
            for (uint k = 0u; k < 3u; ++k) {
                s_lo[k][t] = min(s_lo[k][t], s_lo[k][t + s]);
                s_hi[k][t] = max(s_hi[k][t], s_hi[k][t + s]);
            }
        }
        barrier();
    }
    if (t < 3u && s_lo[t][0] <= s_hi[t][0]) {
        atomicMin(U64Ref(pc.summary + 8ul * t).v, orderedBits64(s_lo[t][0]));
        atomicMax(U64Ref(pc.summary + 24ul + 8ul * t).v, orderedBits64(s_hi[t][0]));
    }
}

// Mode 1: the records the index build reads, and their float bounds.
void convert(uint i, uint t) {
    if (t < 3u) {
        s_flo[t] = 0xffffffffu;
        s_fhi[t] = 0u;
    }
    barrier();
    if (i < pc.n) {
        dvec3 o = dvec3(uint64BitsToDouble(pc.origin[0]), uint64BitsToDouble(pc.origin[1]),
                        uint64BitsToDouble(pc.origin[2]));
        precise dvec3 d = readPoint(i) - o;
        vec3 r = vec3(d);
        vec4At(pc.points, i).v = vec4(r, 0.0);
        for (uint k = 0u; k < 3u; ++k) {
            atomicMin(s_flo[k], orderedBits(r[k]));
            atomicMax(s_fhi[k], orderedBits(r[k]));
        }
    }
    barrier();
    if (t < 3u && s_flo[t] != 0xffffffffu) {
        atomicMin(UintRef(pc.summary + 4ul * t).v, s_flo[t]);
        atomicMax(UintRef(pc.summary + 12ul + 4ul * t).v, s_fhi[t]);
    }
}

void main() {
    if (pc.mode == 0u)
        summarize(gl_GlobalInvocationID.x, gl_LocalInvocationID.x);
    else
        convert(gl_GlobalInvocationID.x, gl_LocalInvocationID.x);
}
