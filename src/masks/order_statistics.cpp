// Selection instead of sorting (order_statistics.hpp).
#include "masks/order_statistics.hpp"

#include "core/nearest_rank.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace rthdist::masks::detail {

double kthSmallest(std::vector<double>& values, size_t k) {
    const auto at = values.begin() + std::ptrdiff_t(k);
    std::nth_element(values.begin(), at, values.end());
    return *at;
}

double percentileLinear(std::vector<double>& values, double p) {
    const size_t n = values.size();
    if (n == 0) return std::numeric_limits<double>::quiet_NaN();
    const double rank = (p / 100.0) * double(n - 1);
    const double lo = std::floor(rank);
    const size_t i = std::min(size_t(lo), n - 1), j = std::min(i + 1, n - 1);
    const double t = rank - lo;
    const double a = kthSmallest(values, i);
    // After selecting i, the (i + 1)-th smallest is the least of what follows it.
    const double b = j == i ? a : *std::min_element(values.begin() + std::ptrdiff_t(j), values.end());
    const double diff = b - a;
    return t >= 0.5 ? b - diff * (1.0 - t) : a + diff * t;
}

double percentilePlastimatch(std::vector<double>& values, double p) {
    const size_t n = values.size();
    if (n == 0) return 0.0;
    double k = std::floor((p / 100.0) * double(n) - 1.0);
    k = std::clamp(k, 0.0, double(n - 1));
    return kthSmallest(values, size_t(k));
}

double percentileNearestRank(std::vector<double>& values, double p) {
    if (values.empty()) return 0.0;
    return kthSmallest(values, core::nearestRankIndex(values.size(), p));
}

size_t countAtMost(const std::vector<double>& values, double limit) {
    return size_t(std::count_if(values.begin(), values.end(), [limit](double v) { return v <= limit; }));
}

}  // namespace rthdist::masks::detail
