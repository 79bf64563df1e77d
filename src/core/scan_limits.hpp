// Which pairs a GPU backend scans whole, query by target, in one submission
// (gpu_algo/small_pairs.hpp) instead of indexing them: the rule as data, read
// by the scan itself and by the route planner (api/route_planner.hpp).
#pragma once

#include <cstdint>

namespace rthdist::core {

struct ScanLimits {
    uint64_t maxSide = 0;  // points of either set
    uint64_t maxWork = 0;  // queries x targets of one direction; 0: no pair is scanned whole

    // Whether a direction of `queries` x `targets` is scanned whole.
    [[nodiscard]] bool takes(uint64_t queries, uint64_t targets) const {
        return queries > 0 && targets > 0 && queries <= maxSide && targets <= maxSide &&
               queries <= maxWork / targets;
    }
    // Both directions of a pair.
    [[nodiscard]] bool takesPair(uint64_t a, uint64_t b) const { return takes(a, b) && takes(b, a); }
};

}  // namespace rthdist::core
