// Statistics of per-point nearest distances: rthdist/stats.hpp has the
// definitions (nearest-rank percentiles, symmetric and pooled variants,
// histogram binning, normalization by the diagonal of the union's box).
#include "rthdist/stats.hpp"

#include "core/nearest_rank.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace rthdist {
namespace {

double diagonalOf(const PointView& points, glm::dvec3& lo, glm::dvec3& hi) {
    for (size_t i = 0; i < points.count; ++i) {
        const glm::dvec3 p = points.at(i);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    if (points.empty()) return 0.0;
    const glm::dvec3 d = hi - lo;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

double diagonalOf(const PointView& points) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    return diagonalOf(points, lo, hi);
}

}  // namespace

double percentileNearestRank(std::span<const double> sorted, double p) {
    if (sorted.empty()) return 0.0;
    return sorted[core::nearestRankIndex(sorted.size(), p)];
}

// A sum in input order with Neumaier's compensation: within about one
// rounding of the exact sum whatever the order (the values are >= 0).
struct CompensatedSum {
    double sum = 0.0, compensation = 0.0;
    void add(double v) {
        const double t = sum + v;
        compensation += std::abs(sum) >= std::abs(v) ? (sum - t) + v : (v - t) + sum;
        sum = t;
    }
    [[nodiscard]] double value() const { return sum + compensation; }
};

DistanceStats distanceStats(std::span<const double> distances, const StatsOptions& options,
                            double histogramLo, double histogramHi) {
    DistanceStats s;
    s.count = distances.size();
    s.histogram.lo = histogramLo;
    s.histogram.hi = histogramHi;
    s.histogram.counts.assign(size_t(std::max(options.histogramBins, 1)), 0);
    if (distances.empty()) return s;
    // One pass for the extremes, the sums and the histogram (none depends on
    // the order), then each percentile's rank selected in ascending rank
    // order (nth_element on what lies above the rank before): a 10M-point
    // direction's sort took ~1 s of the CLI's per-point statistics.
    Histogram& h = s.histogram;
    const size_t bins = h.counts.size();
    const double width = h.hi - h.lo;
    CompensatedSum sum, sumSquares;
    s.min = s.max = distances.front();
    for (const double d : distances) {
        s.min = std::min(s.min, d);
        s.max = std::max(s.max, d);
        sum.add(d);
        sumSquares.add(d * d);
        if (d < h.lo) {
            ++h.below;
        } else if (d > h.hi) {
            ++h.above;
        } else {
            const double at = (d - h.lo) / width * double(bins);
            ++h.counts[std::min(bins - 1, size_t(at))];
        }
    }
    s.mean = sum.value() / double(distances.size());
    s.rms = std::sqrt(sumSquares.value() / double(distances.size()));
    if (options.percentiles.empty()) return s;
    std::vector<std::pair<size_t, size_t>> ranks;  // (rank, position in options.percentiles)
    for (size_t i = 0; i < options.percentiles.size(); ++i)
        ranks.emplace_back(core::nearestRankIndex(distances.size(), options.percentiles[i]), i);
    std::sort(ranks.begin(), ranks.end());
    std::vector<double> work(distances.begin(), distances.end());
    std::vector<double> value(options.percentiles.size());
    size_t from = 0;
    for (const auto& [rank, i] : ranks) {
        if (rank >= from) {
            std::nth_element(work.begin() + std::ptrdiff_t(from), work.begin() + std::ptrdiff_t(rank),
                             work.end());
            from = rank + 1;
        }
        value[i] = work[rank];
    }
    for (size_t i = 0; i < options.percentiles.size(); ++i)
        s.percentiles.push_back({options.percentiles[i], value[i]});
    return s;
}

Result<HausdorffStats> hausdorffStats(const HausdorffResult& result, const PointView& a, const PointView& b,
                                      const StatsOptions& options) {
    if (result.aNearest.distance.size() != a.size() ||
        (!result.directedOnly && result.bNearest.distance.size() != b.size())) {
        return Error{ErrorCode::kInvalidArgument,
                     "hausdorffStats: the result has no per-point distances for these sets "
                     "(Options::perPointDistances)"};
    }
    if (options.histogramBins < 1)
        return Error{ErrorCode::kInvalidArgument, "hausdorffStats: histogramBins < 1"};
    for (double p : options.percentiles) {
        if (!(p >= 0.0 && p <= 100.0)) {
            return Error{ErrorCode::kInvalidArgument, "hausdorffStats: percentile outside [0, 100]"};
        }
    }
    // A fixed range is finite and non-empty: an infinite one put every value
    // in bin 0 under NaN edges, and a NaN or empty one fell back to auto.
    const bool autoRange = options.rangeLo == 0.0 && options.rangeHi == 0.0;
    if (!autoRange && !(std::isfinite(options.rangeLo) && std::isfinite(options.rangeHi) &&
                        options.rangeLo < options.rangeHi)) {
        char text[128];
        std::snprintf(text, sizeof text, "[%g, %g]", options.rangeLo, options.rangeHi);
        return Error{ErrorCode::kInvalidArgument,
                     std::string("hausdorffStats: histogram range [rangeLo, rangeHi] = ") + text +
                         " is not finite with rangeLo < rangeHi (both 0: the automatic range)"};
    }
    const std::vector<double>& da = result.aNearest.distance;
    const std::vector<double> empty;
    const std::vector<double>& db = result.directedOnly ? empty : result.bNearest.distance;
    std::vector<double> pooled;
    if (!result.directedOnly) {
        pooled.reserve(da.size() + db.size());
        pooled.insert(pooled.end(), da.begin(), da.end());
        pooled.insert(pooled.end(), db.begin(), db.end());
    }

    double lo = options.rangeLo, hi = options.rangeHi;
    if (autoRange) {
        lo = 0.0;
        hi = 0.0;
        for (double d : da) hi = std::max(hi, d);
        for (double d : db) hi = std::max(hi, d);
        if (!(hi > 0.0)) hi = 1.0;
    }

    HausdorffStats s;
    s.aToB = distanceStats(da, options, lo, hi);
    s.bToA = distanceStats(db, options, lo, hi);
    s.pooled = distanceStats(pooled, options, lo, hi);
    for (size_t i = 0; i < options.percentiles.size(); ++i) {
        double v = s.aToB.percentiles[i].value;
        if (!result.directedOnly) v = std::max(v, s.bToA.percentiles[i].value);
        s.symmetric.push_back({options.percentiles[i], v});
    }
    glm::dvec3 ulo(std::numeric_limits<double>::infinity()), uhi(-std::numeric_limits<double>::infinity());
    diagonalOf(a, ulo, uhi);
    s.diagonal = diagonalOf(b, ulo, uhi);
    s.diagonalA = diagonalOf(a);
    s.diagonalB = diagonalOf(b);
    return s;
}

bool percentileVariant(const HausdorffStats& stats, const std::string& variant, double p, double& out) {
    const std::vector<Percentile>* list = nullptr;
    if (variant == "max" || variant == "symmetric") list = &stats.symmetric;
    if (variant == "pooled") list = &stats.pooled.percentiles;
    if (list == nullptr) return false;
    for (const Percentile& q : *list) {
        if (q.p == p) {
            out = q.value;
            return true;
        }
    }
    return false;
}

}  // namespace rthdist
