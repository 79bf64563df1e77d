#version 460
// One invocation per point: project it with the orthographic camera of
// SplatPush and write a disc of `radius` pixels into the per-pixel 64-bit
// buffer with atomicMin of (depth bits << 32 | RGBA8). Depth is a
// non-negative float, so its bits order like its values and the nearest
// splat wins every pixel; equal depths keep the smaller colour word.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference2 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "render/splat_shared.h"

layout(local_size_x = RTHDIST_SPLAT_WG) in;
layout(push_constant, scalar) uniform Push { SplatPush pc; };

layout(buffer_reference, scalar, buffer_reference_align = 4) readonly buffer FloatBuf { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer UintBuf { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer U64Buf { uint64_t v[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    FloatBuf points = FloatBuf(pc.points);
    vec3 q = vec3(points.v[3 * i], points.v[3 * i + 1], points.v[3 * i + 2]) -
             vec3(pc.centreX, pc.centreY, pc.centreZ);
    float x = pc.cosYaw * q.x + pc.sinYaw * q.z;
    float z = -pc.sinYaw * q.x + pc.cosYaw * q.z;
    float y = pc.cosPitch * q.y - pc.sinPitch * z;
    float z2 = pc.sinPitch * q.y + pc.cosPitch * z;
    float sx = pc.offX + (x - pc.loX) * pc.scale;
    float sy = pc.offY + (pc.hiY - y) * pc.scale;
    if (!(abs(sx) < 1.0e7 && abs(sy) < 1.0e7)) return;  // off any image (and no int overflow)
    float depth = clamp((pc.hiZ - z2) * pc.invDepthExtent, 0.0, 1.0);
    uint64_t word = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(UintBuf(pc.colours).v[i]);

    float r = pc.radius;
    int x0 = max(int(floor(sx - r)), 0), x1 = min(int(ceil(sx + r)), int(pc.width) - 1);
    int y0 = max(int(floor(sy - r)), 0), y1 = min(int(ceil(sy + r)), int(pc.height) - 1);
    U64Buf pixels = U64Buf(pc.pixels);
    for (int py = y0; py <= y1; ++py) {
        for (int px = x0; px <= x1; ++px) {
            float dx = float(px) + 0.5 - sx, dy = float(py) + 0.5 - sy;
            if (dx * dx + dy * dy > r * r) continue;
            atomicMin(pixels.v[uint(py) * pc.width + uint(px)], word);
        }
    }
}
