#version 460
#extension GL_GOOGLE_include_directive : require
// The candidate search's sweep (CandidateSearch::sweepWork): when few queries
// are open and the targets are few enough, every open query is measured
// against every target, without rays or cells. A workgroup takes one
// (query, block of RTHDIST_WG * RTHDIST_SWEEP_PER_THREAD targets) item at a
// time (a grid-stride loop over queries x blocks); each thread keeps its
// smallest (distance, target index), the group reduces them in shared memory
// (the smallest distance, then the smallest index among equal ones: the
// tie rule of every scan), and one atomicMin per group lowers the query's
// best. Every target is read for every query, so the scan is complete:
// resolve.comp then settles each query at radius +inf. A query that lost
// pairs to a full buffer (RETRY) is open again (nothing is dropped here).
// Why: a far query beside a dense cluster otherwise grows its radius from
// the cluster's spacing to the gap (tens of iterations), and its last pairs
// are cells holding the whole cluster, each scanned by one thread.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SweepPush pc; };

shared uint groupBest;  // float bits (non-negative floats order as their bits)
shared uint groupIndex;

void main() {
    const uint lid = gl_LocalInvocationID.x;
    const uint perBlock = RTHDIST_WG * RTHDIST_SWEEP_PER_THREAD;
    const uint blocks = (pc.n + perBlock - 1u) / perBlock;
    const uint64_t items = uint64_t(blocks) * uint64_t(pc.numActive);
    const uint64_t state = pc.state;
    for (uint64_t item = gl_WorkGroupID.x; item < items; item += gl_NumWorkGroups.x) {
        // Uniform per group: every thread takes the same item.
        const uint slot = uint(item / blocks);
        const uint block = uint(item % blocks);
        const uint qi = uintAt(pc.activeList, slot).v;
        const QueryState st = stateAt(state, qi).v;
        if (block == 0u && lid == 0u && st.status == RTHDIST_RETRY) stateAt(state, qi).v.status = RTHDIST_OPEN;
        if (st.status == RTHDIST_DEAD) continue;  // uniform: one query per item
        const vec3 q = vec4At(pc.queries, qi).v.xyz;
        float best = uintBitsToFloat(0x7f800000u);
        uint bestT = 0xffffffffu;
        const uint first = block * perBlock + lid;
        const uint end = min(pc.n, block * perBlock + perBlock);
        for (uint t = first; t < end; t += RTHDIST_WG) {
            const vec4 tv = vec4At(pc.targets, t).v;
            const float d2 = dist2(q, tv.xyz);
            const uint t_ = floatBitsToUint(tv.w);
            if (d2 < best || (d2 == best && t_ < bestT)) {
                best = d2;
                bestT = t_;
            }
        }
        if (lid == 0u) {
            groupBest = 0x7f800000u;
            groupIndex = 0xffffffffu;
        }
        barrier();
        atomicMin(groupBest, floatBitsToUint(best));
        barrier();
        if (floatBitsToUint(best) == groupBest) atomicMin(groupIndex, bestT);
        barrier();
        if (lid == 0u && groupIndex != 0xffffffffu) {
            const uint64_t packed = packDistIndex(uintBitsToFloat(groupBest), groupIndex);
            if (packed < stateAt(state, qi).v.best) atomicMin(stateAt(state, qi).v.best, packed);
        }
        barrier();  // groupBest is set again for the next item
    }
}
