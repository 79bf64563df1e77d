#version 460
#extension GL_GOOGLE_include_directive : require
// Self-check of one direction (costs one read of the query states): when the
// search ends, every query is EXACT (its NN is known) or DEAD (a real target
// point strictly closer than a value h reaches), and in both cases its best
// squared distance is at most the final maximum. With per-point distances
// every query must be EXACT. A query never visited, or one whose distance was
// lost, breaks this. Thread 0 also copies the witness's records (the query
// slot in the low half of the maximum) and the first threads those of the
// sampled slots, for the host, so the check needs no round trip to learn
// that slot first and no copy commands. In a per-point call every thread writes
// its query's nearest target at the query's original index (nearestOut),
// which the host reads back whole: 4 bytes a query, in the input's order.
// Every query near the maximum is appended to the certificate's band.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CheckPush pc; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.n || (pc.afterCull != 0u && UintRef(pc.counters + RTHDIST_CTR_ACTIVE).v != 0u)) return;
    QueryState st = stateAt(pc.state, i).v;
    uint64_t packed = U64Ref(pc.counters + RTHDIST_CTR_MAX_PACKED).v;
    if (i < pc.samples) {  // the sampled records, before the witness's
        uint slot = pc.n <= RTHDIST_CHECK_SAMPLES
                        ? i
                        : uint(uint64_t(pc.n - 1u) * uint64_t(i) / uint64_t(RTHDIST_CHECK_SAMPLES - 1u));
        uint64_t at = pc.witnessOut - uint64_t(pc.samples - i) * 32ul;
        Vec4Ref(at).v = vec4At(pc.sorted, slot).v;
        StateRef(at + 16ul).v = stateAt(pc.state, slot).v;
    }
    if (i == 0u) {
        uint slot = min(uint(packed & 0xffffffffu), pc.n - 1u);
        vec4At(pc.witnessOut, 0u).v = vec4At(pc.sorted, slot).v;
        StateRef(pc.witnessOut + 16ul).v = stateAt(pc.state, slot).v;
    }
    // A per-point call with a floor (its kill threshold in the counter
    // block): a DEAD query holds a target nearer than it, and reads back as
    // RTHDIST_BELOW_FLOOR.
    float floor2 = FloatRef(pc.counters + RTHDIST_CTR_KILL_FLOOR).v;
    bool belowFloor = pc.perPoint != 0u && st.status == RTHDIST_DEAD;
    if (pc.nearestOut != 0ul)
        uintAt(pc.nearestOut, floatBitsToUint(vec4At(pc.sorted, i).v.w)).v =
            belowFloor ? RTHDIST_BELOW_FLOOR : uint(st.best & 0xffffffffu);
    float maxD2 = packedDist2(packed);
    bool settled = st.status == RTHDIST_EXACT || (st.status == RTHDIST_DEAD && (pc.perPoint == 0u || floor2 > 0.0));
    bool bounded = belowFloor ? packedDist2(st.best) < floor2 : packedDist2(st.best) <= maxD2;
    if (!settled || !bounded) atomicAdd(U64Ref(pc.counters + RTHDIST_CTR_CHECK_BAD).v, 1ul);
    if (belowFloor) return;  // no witness, no band: the call has no result of its own
    uint64_t above = U64Ref(pc.counters + RTHDIST_CTR_ABOVE_OUT).v;
    if (pc.nearestOut != 0ul && above != 0ul) {  // a floor call handed back sparse
        uint k = atomicAdd(UintRef(pc.counters + RTHDIST_CTR_ABOVE_COUNT).v, 1u);
        if (k < UintRef(pc.counters + RTHDIST_CTR_ABOVE_CAPACITY).v)
            uvec2At(above, k).v = uvec2(floatBitsToUint(vec4At(pc.sorted, i).v.w), uint(st.best & 0xffffffffu));
    }
    // The certificate's band (core/certificate.hpp): every query whose best
    // lies within 2e of the maximum, with its best target. The threshold is
    // rounded down (a relative 2^-20 on the maximum and on the square), so it
    // is never above (hf - 2e)^2 in real numbers.
    if (pc.bandOut != 0ul) {
        if (packedDist2(st.best) >= shrunkDist2(maxD2, 2.0 * pc.bandSlack)) {
            uint k = atomicAdd(UintRef(pc.bandOut).v, 1u);
            if (k < pc.bandCapacity)
                uvec2At(pc.bandOut + 8ul, k).v = uvec2(floatBitsToUint(vec4At(pc.sorted, i).v.w), uint(st.best & 0xffffffffu));
        }
    }
}
