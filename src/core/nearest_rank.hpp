// The nearest-rank percentile's position, shared by the point-set statistics
// (rthdist/stats.hpp percentileNearestRank, on sorted distances) and the masks'
// medpy / default conventions (masks/order_statistics.hpp, by selection).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace rthdist::core {

// The 0-based index of the p-th percentile (p in [0, 100]) of n > 0 sorted
// values by nearest rank: the ceil(p n / 100)-th smallest, at least the first.
[[nodiscard]] inline size_t nearestRankIndex(size_t n, double p) {
    const double count = double(n);
    return size_t(std::clamp(std::ceil(p * count / 100.0), 1.0, count)) - 1;
}

}  // namespace rthdist::core
