#version 460
#extension GL_GOOGLE_include_directive : require
// Test probe of the record accessors of common.glsl: the address each one
// forms for a given index, written out without touching the record, so the
// 64-bit offset arithmetic is checked at 2^28, 2^31 and 2^32 - 1 records
// without allocating 4 GiB.
#include "common.glsl"
layout(local_size_x = 1) in;
layout(push_constant) uniform Push {
    uint64_t base;
    uint64_t out_;  // uint64[7]
    uint index;
} pc;

void main() {
    uint i = pc.index;
    u64At(pc.out_, 0).v = uint64_t(vec4At(pc.base, i));
    u64At(pc.out_, 1).v = uint64_t(uintAt(pc.base, i));
    u64At(pc.out_, 2).v = uint64_t(uvec2At(pc.base, i));
    u64At(pc.out_, 3).v = uint64_t(u64At(pc.base, i));
    u64At(pc.out_, 4).v = uint64_t(cellAt(pc.base, i));
    u64At(pc.out_, 5).v = uint64_t(stateAt(pc.base, i));
    u64At(pc.out_, 6).v = uint64_t(floatAt(pc.base, uint64_t(i) * 6ul + 5ul));
}
