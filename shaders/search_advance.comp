#version 460
#extension GL_GOOGLE_include_directive : require
// Between two radii of the candidate search recorded in one submission: logs
// the radius just run (queries searched, queries going on, pairs appended),
// then sets up the next: it searches the queries going on (resolve.comp's
// list), or none once the pair buffer overflowed (the host then resumes from
// the logged radius with more room, as after a single radius), and writes
// the dispatch sizes of its search and resolve. The queries going on after
// the last radius that searched any are the count the host goes on with;
// the self-check recorded behind the radii (an indirect dispatch) gets its
// groups only when that count is 0, else none.
#include "common.glsl"
layout(local_size_x = 1) in;
layout(push_constant) uniform Push { SearchAdvancePush pc; };

void main() {
    uint64_t c = pc.counters;
    uint searched = UintRef(c + RTHDIST_CTR_SEARCH_ACTIVE).v;
    uint next = UintRef(c + RTHDIST_CTR_NEXT_ACTIVE).v;
    uint64_t pairs = U64Ref(c + RTHDIST_CTR_PAIRS).v;
    uint64_t entry = c + RTHDIST_CTR_SEARCH_LOG + uint64_t(pc.iteration) * 16ul;
    UintRef(entry).v = searched;
    UintRef(entry + 4ul).v = next;
    U64Ref(entry + 8ul).v = pairs;
    uint open = searched > 0u ? next : UintRef(c + RTHDIST_CTR_SEARCH_OPEN).v;
    UintRef(c + RTHDIST_CTR_SEARCH_OPEN).v = open;
    UintRef(c + RTHDIST_CTR_CHECK_ARGS).v = open == 0u ? pc.checkGroups : 0u;
    UintRef(c + RTHDIST_CTR_CHECK_ARGS + 4ul).v = 1u;
    UintRef(c + RTHDIST_CTR_CHECK_ARGS + 8ul).v = 1u;
    uint searchedNext = pairs > uint64_t(pc.pairCapacity) ? 0u : next;
    UintRef(c + RTHDIST_CTR_SEARCH_ACTIVE).v = searchedNext;
    // The next radius's dispatch sizes: groups of the search (ray queries)
    // and of the resolve, and the rays of a trace.
    uvec3 groups = uvec3((searchedNext + RTHDIST_WG - 1u) / RTHDIST_WG, 1u, 1u);
    uvec3 rays = uvec3(searchedNext, 1u, 1u);
    for (uint a = 0u; a < 3u; ++a) {
        UintRef(c + RTHDIST_CTR_SEARCH_ARGS + 4ul * a).v = groups[a];
        UintRef(c + RTHDIST_CTR_SEARCH_ARGS + 12ul + 4ul * a).v = rays[a];
    }
    UintRef(c + RTHDIST_CTR_NEXT_ACTIVE).v = 0u;
    U64Ref(c + RTHDIST_CTR_PAIRS).v = 0ul;
}
