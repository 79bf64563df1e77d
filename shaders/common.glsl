// Common declarations of rthdist's shaders: buffer references over device
// addresses, the Morton key, and the exact distance helpers. Distances are
// `precise` (no FMA contraction) and formed from raw float differences, so
// they match the host's double recomputation up to float rounding.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference2 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_scalar_block_layout : require

#include "rthdist_morton.h"
#include "rthdist_shared.h"

// Every record is reached at a 64-bit byte offset from its buffer's device
// address: base + uint64_t(index) * size. An array index of a buffer reference
// is a 32-bit access-chain operand, and drivers may form index * stride in 32
// bits: with 16-byte records that wraps at 2^28 records (4 GiB), silently
// reading and writing other records (issue: wrong H at 300M points on NVIDIA).
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4Ref { vec4 v; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Uvec4Ref { uvec4 v; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer UintRef { uint v; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer FloatRef { float v; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uvec2Ref { uvec2 v; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer U64Ref { uint64_t v; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer CellRef { Cell v; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer StateRef { QueryState v; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer LeafGroupRef { LeafGroup v; };

Vec4Ref vec4At(uint64_t base, uint i) { return Vec4Ref(base + uint64_t(i) * 16ul); }
Uvec4Ref uvec4At(uint64_t base, uint i) { return Uvec4Ref(base + uint64_t(i) * 16ul); }
UintRef uintAt(uint64_t base, uint i) { return UintRef(base + uint64_t(i) * 4ul); }
FloatRef floatAt(uint64_t base, uint64_t i) { return FloatRef(base + i * 4ul); }
Uvec2Ref uvec2At(uint64_t base, uint i) { return Uvec2Ref(base + uint64_t(i) * 8ul); }
U64Ref u64At(uint64_t base, uint i) { return U64Ref(base + uint64_t(i) * 8ul); }
CellRef cellAt(uint64_t base, uint i) { return CellRef(base + uint64_t(i) * 32ul); }
StateRef stateAt(uint64_t base, uint i) { return StateRef(base + uint64_t(i) * 16ul); }
LeafGroupRef groupAt(uint64_t base, uint i) { return LeafGroupRef(base + uint64_t(i) * 32ul); }

// The item of thread t in a pass over n items in space order whose atomics
// follow the items' cells: the 32 threads of a warp take items ceil(n / 32) apart
// (lane * rows + t / 32), so that items in space order (the out-of-core
// pieces' gathered points) do not send a warp's atomics to a few lines of
// the dense key table. A bijection of [0, 32 rows) onto itself; n (none)
// for a thread past the items. The host dispatches spreadThreads(n).
uint spreadItem(uint t, uint n) {
    uint rows = (n + 31u) / 32u;
    uint row = t >> 5u;
    if (row >= rows) return n;
    uint p = (t & 31u) * rows + row;
    return p < n ? p : n;
}

// The queries the radius in flight searches (set by the host, then by
// search_advance.comp between the radii of one submission), at most the
// slots dispatched.
uint searchedCount(uint64_t counters, uint dispatched) {
    return min(dispatched, UintRef(counters + RTHDIST_CTR_SEARCH_ACTIVE).v);
}

// spreadBits and mortonEncode: rthdist_morton.h (the C++ side's too).
uint mortonKey(uvec3 c) { return mortonEncode(c.x, c.y, c.z); }

vec3 gridOrigin(GridParams g) { return vec3(g.originX, g.originY, g.originZ); }

// Unclamped integer cell coordinate of p (may lie outside the grid).
ivec3 cellOfUnclamped(vec3 p, GridParams g) {
    precise vec3 rel = (p - gridOrigin(g)) * g.invCellSize;
    return ivec3(floor(clamp(rel, vec3(-1.0e8), vec3(1.0e8))));
}

uvec3 cellOfClamped(vec3 p, GridParams g) {
    ivec3 c = cellOfUnclamped(p, g);
    return uvec3(clamp(c, ivec3(0), ivec3(int(g.cellsPerAxis) - 1)));
}

float dist2(vec3 a, vec3 b) {
    precise vec3 d = a - b;
    precise float r = d.x * d.x + d.y * d.y + d.z * d.z;
    return r;
}

// Squared Euclidean distance from q to the box [lo, hi] (0 inside).
float boxDist2(vec3 q, vec3 lo, vec3 hi) {
    precise vec3 d = max(max(lo - q, q - hi), vec3(0.0));
    precise float r = d.x * d.x + d.y * d.y + d.z * d.z;
    return r;
}

// Packed (squared distance, index) for 64-bit atomics; float bits of a
// non-negative float order like the float.
uint64_t packDistIndex(float d2, uint index) {
    return (uint64_t(floatBitsToUint(d2)) << 32) | uint64_t(index);
}
float packedDist2(uint64_t p) { return uintBitsToFloat(uint(p >> 32)); }

// atomicMax of the running maximum at maxPacked, skipped when a plain read
// already shows one at least as large: the maximum only grows, so a stale
// read costs only the atomic, and the threads that settle a query below
// the maximum (most of them) do not queue on the one address (the plain
// read deadThreshold relies on too).
void raiseMax(uint64_t maxPacked, uint64_t packed) {
    if (packed > U64Ref(maxPacked).v) atomicMax(U64Ref(maxPacked).v, packed);
}

// (sqrt(d2) - by)^2, rounded down (a relative 2^-20 on the root and on the
// square; 0 when by exceeds the root): the certificate's band threshold
// (check_queries.comp, by = 2e) and the kill threshold under it
// (deadThreshold, by = 3e), one formula so that the second stays below the first.
float shrunkDist2(float d2, float by) {
    float lo = max(sqrt(d2) * (1.0 - 1.0 / 1048576.0) - by, 0.0);
    return lo * lo * (1.0 - 1.0 / 1048576.0);
}

// The threshold below which a query cannot raise h: the larger of the exact
// running maximum (has a witness) and the witness-less lower bound, lowered
// by 3e (e: the certificate's slack in the counter block, 0 where none), so
// that a query killed below it lies below the band the self-check hands to
// the certificate (check_queries.comp: 2e under the final maximum, which
// is at least this one): dead queries need no brute force in double.
// A negative lowerBound2 turns the early break off (per-point distances),
// but for the call's floor (core/per_point_floor.hpp: 0 where none), a
// threshold given by the host, not raised by the call's own maximum.
float deadThreshold(uint64_t maxPacked, float lowerBound2) {
    if (lowerBound2 < 0.0) return FloatRef(maxPacked + uint64_t(RTHDIST_CTR_KILL_FLOOR - RTHDIST_CTR_MAX_PACKED)).v;
    uint64_t m = U64Ref(maxPacked).v;
    float thr = max(packedDist2(m), lowerBound2);
    float e = FloatRef(maxPacked + uint64_t(RTHDIST_CTR_KILL_SLACK - RTHDIST_CTR_MAX_PACKED)).v;
    return e == 0.0 ? thr : shrunkDist2(thr, 3.0 * e);
}

// Order-preserving uint of a float (for atomicMin/atomicMax of floats) and back.
uint orderedBits(float f) {
    uint b = floatBitsToUint(f);
    return (b & 0x80000000u) != 0u ? ~b : b | 0x80000000u;
}
float fromOrderedBits(uint u) { return uintBitsToFloat((u & 0x80000000u) != 0u ? u & 0x7fffffffu : ~u); }
