// Order statistics of a direction's distances without sorting them: each
// value is the one a sort followed by an index would give (the same element,
// bit for bit), found by selection, so a mask pair with 10^5-10^6 boundary
// voxels per side does not pay an O(n log n) sort per direction. Below 2^15
// values: std::nth_element (the values are reordered). From
// 2^15 on, with more than one thread: parallel passes find the range, a
// histogram of 4096 equal buckets over it, and the values of the bucket
// that holds the rank, and nth_element runs on those (the values are left as
// they are).
// `threads`: 0 = all hardware threads. Values must not be NaN. `range`, when
// given, must be the exact least and greatest of the values (a direction
// knows them from its recomputed distances): the parallel passes then skip
// finding it.
// Internal to rthdist_masks.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <utility>

namespace rthdist::masks::detail {

using ValueRange = std::optional<std::pair<double, double>>;  // least, greatest

// The k-th smallest (0-based) of non-empty `values`.
[[nodiscard]] double kthSmallest(std::span<double> values, size_t k, int threads, ValueRange range = {});

// Linear interpolation between order statistics (numpy.percentile's and
// torch.quantile's default): rank q (n - 1), lerp written as numpy writes it.
// NaN when empty.
[[nodiscard]] double percentileLinear(std::span<double> values, double p, int threads, ValueRange range = {});

// torch.quantile(t, p / 100) of a float32 tensor t (MONAI's HD-p): the rank
// q (n - 1) computed in float32 as torch computes it (q = float(p / 100),
// n - 1 rounded to float, their product rounded), truncated to the lower
// index, its float32 fraction the weight of the next order statistic,
// torch's lerp (w < 0.5: a + w (b - a), else b - (b - a)(1 - w)) evaluated in
// double. Ranks and weights are torch's; the values are the double
// distances (MONAI's are their float32 roundings). NaN when empty.
[[nodiscard]] double percentileTorchFloat32(std::span<double> values, double p, int threads,
                                            ValueRange range = {});

// plastimatch: the k-th smallest (0-based), k = floor(f n - 1) clamped to [0, n-1], f = p / 100,
// evaluated in float32 as plastimatch does; 0 when empty.
[[nodiscard]] double percentilePlastimatch(std::span<double> values, double p, int threads,
                                           ValueRange range = {});

// Nearest rank (rthdist/stats.hpp percentileNearestRank): the ceil(p n / 100)-th
// smallest, rank clamped to [1, n]; 0 when empty.
[[nodiscard]] double percentileNearestRank(std::span<double> values, double p, int threads,
                                           ValueRange range = {});

// How many values are <= limit.
[[nodiscard]] size_t countAtMost(std::span<const double> values, double limit, int threads);

}  // namespace rthdist::masks::detail
