// NumPy's summation and DeepMind's area-weighted percentile (area_weighted.hpp).
#include "masks/area_weighted.hpp"

#include <algorithm>
#include <limits>

namespace rthdist::masks::detail {

double numpySum(std::span<const double> a) {
    const size_t n = a.size();
    if (n < 8) {
        double sum = 0.0;
        for (double x : a) sum += x;
        return sum;
    }
    if (n <= 128) {
        double r[8];
        for (size_t j = 0; j < 8; ++j) r[j] = a[j];
        size_t i = 8;
        for (; i < n - n % 8; i += 8)
            for (size_t j = 0; j < 8; ++j) r[j] += a[i + j];
        double sum = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; ++i) sum += a[i];
        return sum;
    }
    size_t half = n / 2;
    half -= half % 8;
    return numpySum(a.first(half)) + numpySum(a.subspan(half));
}

double areaWeightedPercentile(std::span<const double> d, std::span<const double> areas, double p) {
    const size_t n = d.size();
    if (n == 0) return std::numeric_limits<double>::infinity();
    const double total = numpySum(areas);
    const double threshold = p / 100.0;
    double cumulative = 0.0;
    for (size_t i = 0; i < n; ++i) {
        cumulative += areas[i];
        if (cumulative / total >= threshold) return d[i];
    }
    return d[n - 1];
}

}  // namespace rthdist::masks::detail
