// One direction h(Q, T) of a pair as its stages see it: the neighbourhood
// pass (neighbourhood_pass.hpp), the candidate search and refinement
// (candidate_search.hpp, refinement.hpp), the self-check (query_check.hpp).
#pragma once

#include "core/certificate.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpu_algo/point_index.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu_algo {

// What the stages of one direction h(Q, T) share. Each direction of a
// pair counts into a counter block of its own and keeps its query states
// in buffers of its own (tag), so both can be culled in one submission.
struct DirectionRun {
    const PointIndex& Q;
    PointIndex& T;
    SetPoints& qPts;  // where the host reads what the device holds (set_points.hpp)
    SetPoints& tPts;
    const CounterBlock& blk;
    PerPoint* perPoint = nullptr;
    bool perPointDistances = true;  // false: perPoint's nearest only (CallOptions::perPointNearestOnly)
    Directed out{};
    double lowerBound2Exact = 0.0;  // the boxes' bound (double), for the witness check
    float lowerBound2 = 0.0f;       // < 0: per-point (no early break but killFloor2's)
    float killFloor2 = 0.0f;        // per-point: DEAD below it (core/per_point_floor.hpp; 0: none)
    float epsilon = 0.0f;
    Buffer* state = nullptr;                   // QueryState per query slot
    Buffer* active[2] = {nullptr, nullptr};    // active slots, ping-pong
    int cur = 0;                               // active[cur] holds this iteration's slots
    Buffer* nearest = nullptr;                 // per-point: uint nearest target per query (device)
    Buffer* nearestHost = nullptr;             // per-point: `nearest` copied by each self-check
    Buffer* above = nullptr;                   // a floor call: its queries above the floor (sparse)
    Buffer* aboveHost = nullptr;               // `above` copied by each self-check
    uint32_t aboveCapacity = 0;                // entries `above` holds
    std::vector<uint32_t> checkSlots{};        // the self-check's sampled query slots
    Buffer* band = nullptr;                    // host: the certificate's band (certificate_pass.hpp)
    uint32_t bandCapacity = 0;                 // queries `band` holds
    double slack = 0.0;                        // the certificate's e, search units
    std::vector<core::BandNearest> settled{};  // band queries the certificate settled in double
    [[nodiscard]] std::string name() const { return Q.name + "->" + T.name; }
    // Takes nearestHost, `nearest`'s host copy (Q.n words of read-back
    // memory), from the workspace slot of `direction`.
    void takeNearestHost(Workspace& ws, size_t direction) {
        nearestHost = &ws.grow(ws.scratch.directions[direction].nearestHost, VkDeviceSize(Q.n) * 4,
                               name() + ".nearestHost", MemoryKind::kReadback);
    }
};

// The addresses that the candidate search and the refinement of one radius
// both push (SearchPush and RefinePush begin with the same fields).
template <class Push>
void setRadiusAddresses(Push& p, const DirectionRun& d, const PointIndex::Level& lv, const Buffer& pairs) {
    p.queries = d.Q.sorted->address();
    p.targets = d.T.sorted->address();
    p.cells = lv.cells->address();
    p.state = d.state->address();
    p.activeList = d.active[d.cur]->address();
    p.pairs = pairs.address();
    p.counters = d.blk.device;
    p.maxPacked = d.blk.addr(RTHDIST_CTR_MAX_PACKED);
}

}  // namespace rthdist::gpu_algo
