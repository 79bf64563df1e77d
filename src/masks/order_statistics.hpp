// Order statistics of a direction's distances without sorting them: each
// value is the one a sort followed by an index would give (the same element,
// bit for bit), found by selection (std::nth_element, O(n) per query), so a
// mask pair with 10^5-10^6 boundary voxels per side does not pay an
// O(n log n) sort per direction. The vectors are reordered (never resized).
// Internal to rthdist_masks.
#pragma once

#include <cstddef>
#include <vector>

namespace rthdist::masks::detail {

// The k-th smallest (0-based) of non-empty `values`.
[[nodiscard]] double kthSmallest(std::vector<double>& values, size_t k);

// Linear interpolation between order statistics (numpy.percentile's and
// torch.quantile's default): rank q (n - 1), lerp written as numpy writes it.
// NaN when empty.
[[nodiscard]] double percentileLinear(std::vector<double>& values, double p);

// plastimatch: the k-th smallest (0-based), k = floor(f n - 1) clamped to [0, n-1]; 0 when empty.
[[nodiscard]] double percentilePlastimatch(std::vector<double>& values, double p);

// Nearest rank (rthdist/stats.hpp percentileNearestRank): the ceil(p n / 100)-th
// smallest, rank clamped to [1, n]; 0 when empty.
[[nodiscard]] double percentileNearestRank(std::vector<double>& values, double p);

// How many values are <= limit.
[[nodiscard]] size_t countAtMost(const std::vector<double>& values, double limit);

}  // namespace rthdist::masks::detail
