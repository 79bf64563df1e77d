// Selection-based order statistics (masks/order_statistics.hpp) against the
// same rules written on a sorted copy, on values with many ties (distances of
// voxel lattices repeat) and on every size from 1 to 40.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "masks/order_statistics.hpp"

namespace rthdist::masks::detail {
namespace {

double sortedLinear(const std::vector<double>& s, double p) {
    const double rank = (p / 100.0) * double(s.size() - 1);
    const double lo = std::floor(rank);
    const size_t i = std::min(size_t(lo), s.size() - 1), j = std::min(i + 1, s.size() - 1);
    const double t = rank - lo, diff = s[j] - s[i];
    return t >= 0.5 ? s[j] - diff * (1.0 - t) : s[i] + diff * t;
}

// plastimatch's rank: its float fraction times the count, minus 1, floored, in float32.
double sortedPlastimatch(const std::vector<double>& s, double p) {
    const float rank = std::floor(float(p / 100.0) * float(s.size()) - 1.0f);
    const double k = std::clamp(double(rank), 0.0, double(s.size() - 1));
    return s[size_t(k)];
}

TEST(OrderStatistics, PlastimatchsRankIsItsFloat32One) {
    // 0.57 * 100 - 1 is 55.99999999999999 in double: floor 55; in float32
    // (and exactly) 56. The same for p = 29 of 100 and p = 70 of 90.
    std::vector<double> values(100);
    for (size_t i = 0; i < values.size(); ++i) values[i] = double(99 - i);  // value = rank
    std::vector<double> work = values;
    EXPECT_EQ(percentilePlastimatch(work, 57.0, 2), 56.0);
    work = values;
    EXPECT_EQ(percentilePlastimatch(work, 29.0, 2), 28.0);
    std::vector<double> ninety(values.end() - 90, values.end());
    EXPECT_EQ(percentilePlastimatch(ninety, 70.0, 2), 62.0);
}

double sortedNearestRank(const std::vector<double>& s, double p) {
    const double rank = std::clamp(std::ceil(p * double(s.size()) / 100.0), 1.0, double(s.size()));
    return s[size_t(rank) - 1];
}

TEST(OrderStatistics, SelectionEqualsTheSortedRule) {
    std::mt19937 rng(7);
    const std::vector<double> ps{0.0, 1.0, 5.0, 25.0, 50.0, 90.0, 95.0, 99.0, 99.9, 100.0, 33.3};
    for (size_t n = 1; n <= 40; ++n) {
        for (int trial = 0; trial < 5; ++trial) {
            std::vector<double> values(n);
            // sqrt of small integers: the ties of lattice distances.
            for (double& v : values) v = std::sqrt(double(rng() % 12));
            std::vector<double> sorted = values;
            std::sort(sorted.begin(), sorted.end());
            for (double p : ps) {
                std::vector<double> work = values;
                EXPECT_EQ(percentileLinear(work, p, 2), sortedLinear(sorted, p)) << n << " p" << p;
                work = values;
                EXPECT_EQ(percentilePlastimatch(work, p, 2), sortedPlastimatch(sorted, p)) << n << " p" << p;
                work = values;
                EXPECT_EQ(percentileNearestRank(work, p, 2), sortedNearestRank(sorted, p)) << n << " p" << p;
                // Reused without restoring the order (several percentiles in a row).
                EXPECT_EQ(percentileLinear(work, p, 2), sortedLinear(sorted, p)) << n << " p" << p;
            }
            for (double limit : {-1.0, 0.0, 1.0, std::sqrt(2.0), 10.0})
                EXPECT_EQ(countAtMost(values, limit, 2),
                          size_t(std::upper_bound(sorted.begin(), sorted.end(), limit) - sorted.begin()));
        }
    }
}

// From 2^15 values on, the bracketed parallel selection: lattice distances
// with many ties, a spread of distinct values, and a heavy tail (the few far
// outliers of a noisy mask), against the sorted rule on every percentile,
// with the range found by the selection and given by the caller.
TEST(OrderStatistics, ParallelSelectionEqualsTheSortedRule) {
    std::mt19937 rng(11);
    const std::vector<double> ps{0.0, 0.001, 5.0, 50.0, 90.0, 95.0, 99.0, 99.99, 100.0};
    for (size_t n : {size_t(1) << 15, size_t(100003), size_t(400000)}) {
        for (int shape = 0; shape < 4; ++shape) {
            std::vector<double> values(n);
            for (double& v : values) {
                const uint32_t r = rng();
                v = shape == 0   ? std::sqrt(double(r % 40))
                    : shape == 1 ? double(r) / 4096.0
                    : shape == 2 ? (r % 1000 == 0 ? 100.0 + double(r % 997) : std::sqrt(double(r % 9)))
                                 : (r % 7 == 0 ? 4.9e-324 * double(r % 5) : 0.0);  // a subnormal range
            }
            std::vector<double> sorted = values;
            std::sort(sorted.begin(), sorted.end());
            // The range given (as a direction knows it) or found: the same values.
            const ValueRange range{{sorted.front(), sorted.back()}};
            for (double p : ps) {
                std::vector<double> work = values;
                EXPECT_EQ(percentileLinear(work, p, 2), sortedLinear(sorted, p))
                    << n << " shape " << shape << " p" << p;
                EXPECT_EQ(percentilePlastimatch(work, p, 2), sortedPlastimatch(sorted, p)) << n << " p" << p;
                EXPECT_EQ(percentileNearestRank(work, p, 2), sortedNearestRank(sorted, p)) << n << " p" << p;
                EXPECT_EQ(percentileLinear(work, p, 2, range), sortedLinear(sorted, p)) << n << " p" << p;
                EXPECT_EQ(percentilePlastimatch(work, p, 2, range), sortedPlastimatch(sorted, p))
                    << n << " p" << p;
                EXPECT_EQ(percentileNearestRank(work, p, 2, range), sortedNearestRank(sorted, p))
                    << n << " p" << p;
            }
            EXPECT_EQ(countAtMost(values, 2.0, 2),
                      size_t(std::upper_bound(sorted.begin(), sorted.end(), 2.0) - sorted.begin()));
        }
    }
}

TEST(OrderStatistics, EmptyValuesFollowTheConventions) {
    std::vector<double> none;
    EXPECT_TRUE(std::isnan(percentileLinear(none, 95.0, 2)));
    EXPECT_EQ(percentilePlastimatch(none, 95.0, 2), 0.0);
    EXPECT_EQ(percentileNearestRank(none, 95.0, 2), 0.0);
    EXPECT_EQ(countAtMost(none, 1.0, 2), 0u);
}

}  // namespace
}  // namespace rthdist::masks::detail
