// The GPU engine's self-check (issue: a wrong H with exit 0 at 300M points):
// invariants that every correct run satisfies, checked on every call at the
// cost of one read of the sorted points and of the query states on the
// device, plus a few dozen records compared with the host's copy. A failed
// check ends the call with ErrorCode::kInternal and the reason, never with a
// number. The host-side halves live here as pure functions (tested alone).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpu_algo/set_points.hpp"

#include "rthdist_shared.h"

namespace rthdist::gpu_algo {

class SelfCheckError : public std::runtime_error {
public:
    explicit SelfCheckError(const std::string& why) : std::runtime_error("self-check failed: " + why) {}
};

// `count` slots spread evenly over [0, n), the first and the last among them
// (all of them when n <= count).
[[nodiscard]] std::vector<uint32_t> sampleSlots(uint32_t n, uint32_t count);

// The index's verdict from check_index.comp: "" when it holds, else why not.
// badRecords: sorted records off their key or out of key order; indexSum:
// the sum of the original indices (must be n(n-1)/2); cells: the count the
// build wrote (must fit the cell buffer's capacity).
[[nodiscard]] std::string indexCheckFailure(uint64_t n, uint64_t badRecords, uint64_t indexSum,
                                            uint64_t expectedSum, uint64_t cells, uint64_t cellCapacity);

// One query's device records: its sorted point (xyz, w = original index
// bits) and its final state.
struct SampledQuery {
    uint32_t slot = 0;
    float sorted[4] = {0, 0, 0, 0};
    shared::QueryState state{};
};

// Compares sampled device records of a finished direction with the host's
// points (those uploaded or, for device input, copied back from the
// embedder's buffer: qPts queries, tPts targets): the record holds the
// point it claims, its state is settled (EXACT, or DEAD without perPoint),
// its best names a real target whose float squared distance (computed as the
// shaders do) equals the stored one, and it is not above the final maximum
// maxPacked. The last sample is the witness: its best is the maximum.
// A per-point call with a floor (killFloor2 > 0): a DEAD record is settled
// when its best lies below the floor, and the witness is not checked (the
// call has none). "" when every sample holds, else the first failure.
[[nodiscard]] std::string sampledQueryFailure(std::span<const SampledQuery> samples, const SetPoints& qPts,
                                              const SetPoints& tPts, uint64_t maxPacked, bool perPoint,
                                              float killFloor2 = 0.0f);
// The same over host arrays.
[[nodiscard]] inline std::string sampledQueryFailure(std::span<const SampledQuery> samples,
                                                     std::span<const glm::vec3> qPts,
                                                     std::span<const glm::vec3> tPts, uint64_t maxPacked,
                                                     bool perPoint) {
    SetPoints q, t;
    q.useHost(qPts);
    t.useHost(tPts);
    return sampledQueryFailure(samples, q, t, maxPacked, perPoint);
}

// The reported value against the device's: the double distance of the
// witness pair must agree with the maximum's float squared distance
// (maxPacked) to float rounding, and must not lie below the witness-less
// lower bound (the farthest query from the targets' box). "" when it holds.
[[nodiscard]] std::string witnessFailure(double distance, uint64_t maxPacked, double lowerBound);

}  // namespace rthdist::gpu_algo
