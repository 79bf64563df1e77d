// Area-weighted statistics of DeepMind surface-distance, in the floating-point
// order NumPy evaluates them (so a fraction that lands within rounding of a
// threshold falls the same side as in DeepMind's own run). Internal to
// rthdist_masks.
#pragma once

#include <span>

namespace rthdist::masks::detail {

// numpy.sum of a contiguous float64 array, bit for bit: pairwise summation
// (under 8 values a plain loop; up to 128 eight interleaved partial sums;
// above, two halves split at a multiple of 8).
[[nodiscard]] double numpySum(std::span<const double> values);

// DeepMind's percentile of distances weighted by surfel area
// (compute_robust_hausdorff): with d sorted ascending (ties by area) and a the
// matching areas, the cumulative fraction c_i = cumsum(a)_i / numpySum(a) and
// the value d[min(i, n - 1)] for the first i with c_i >= p / 100 (no
// interpolation). n = 0 gives +inf, as DeepMind does.
[[nodiscard]] double areaWeightedPercentile(std::span<const double> sortedDistances,
                                            std::span<const double> areas, double p);

}  // namespace rthdist::masks::detail
