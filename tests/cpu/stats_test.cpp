// Statistics (rthdist/stats.hpp) against references computed here from the
// CPU per-point distances: mean/RMS by plain sums, percentiles by the
// "smallest value with at least p% of the values at or below it" form of the
// nearest-rank definition (a different computation of the same quantity),
// histograms by counting, the diagonal from the union's box.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common/oracle_cases.hpp"
#include "cpu/cpu_hausdorff.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::test {
namespace {

// The smallest v in `values` with #{x <= v} * 100 >= p * n; the minimum for p = 0.
double referencePercentile(const std::vector<double>& values, double p) {
    const double n = double(values.size());
    double best = INFINITY;
    for (double v : values) {
        const double atOrBelow =
            double(std::count_if(values.begin(), values.end(), [&](double x) { return x <= v; }));
        if (atOrBelow * 100.0 >= p * n && v < best) best = v;
    }
    return best;
}

void expectStatsMatch(const std::vector<double>& d, const DistanceStats& s, const StatsOptions& o) {
    ASSERT_EQ(s.count, d.size());
    if (d.empty()) return;
    long double sum = 0, sumSquares = 0;
    for (double x : d) {
        sum += x;
        sumSquares += (long double)x * x;
    }
    const double mean = double(sum / d.size()), rms = double(std::sqrt(sumSquares / d.size()));
    EXPECT_EQ(s.min, *std::min_element(d.begin(), d.end()));
    EXPECT_EQ(s.max, *std::max_element(d.begin(), d.end()));
    EXPECT_NEAR(s.mean, mean, 1e-12 * std::max(1.0, s.max));
    EXPECT_NEAR(s.rms, rms, 1e-12 * std::max(1.0, s.max));
    ASSERT_EQ(s.percentiles.size(), o.percentiles.size());
    for (size_t i = 0; i < o.percentiles.size(); ++i) {
        EXPECT_EQ(s.percentiles[i].p, o.percentiles[i]);
        EXPECT_EQ(s.percentiles[i].value, referencePercentile(d, o.percentiles[i]))
            << "p " << o.percentiles[i];
    }
    const Histogram& h = s.histogram;
    ASSERT_EQ(h.counts.size(), size_t(o.histogramBins));
    uint64_t total = h.below + h.above;
    for (uint64_t c : h.counts) total += c;
    EXPECT_EQ(total, d.size());
    const double w = (h.hi - h.lo) / double(h.counts.size());
    for (size_t bin = 0; bin < h.counts.size(); ++bin) {
        const double lo = h.lo + w * double(bin);
        uint64_t want = 0;
        for (double x : d) {
            if (x < h.lo || x > h.hi) continue;
            size_t at =
                std::min(h.counts.size() - 1, size_t((x - h.lo) / (h.hi - h.lo) * double(h.counts.size())));
            if (at == bin) ++want;
        }
        EXPECT_EQ(h.counts[bin], want) << "bin " << bin << " from " << lo;
    }
}

TEST(Stats, NearestRankDefinition) {
    const std::vector<double> v{1, 2, 3, 4};
    EXPECT_EQ(percentileNearestRank(v, 0), 1);
    EXPECT_EQ(percentileNearestRank(v, 25), 1);
    EXPECT_EQ(percentileNearestRank(v, 26), 2);
    EXPECT_EQ(percentileNearestRank(v, 50), 2);
    EXPECT_EQ(percentileNearestRank(v, 95), 4);
    EXPECT_EQ(percentileNearestRank(v, 100), 4);
    std::vector<double> twenty(20);
    for (int i = 0; i < 20; ++i) twenty[size_t(i)] = i + 1;
    EXPECT_EQ(percentileNearestRank(twenty, 95), 19);  // rank ceil(0.95 * 20) = 19 exactly
}

TEST(Stats, OracleCasesAgainstReference) {
    const std::vector<OracleCase> all = makeOracleCases();
    StatsOptions o;
    o.percentiles = {0, 5, 50, 90, 95, 99, 100};
    o.histogramBins = 7;
    size_t checked = 0;
    for (size_t k = 0; k < all.size(); k += 11) {
        const OracleCase& c = all[k];
        if (c.a.size() + c.b.size() > 6000) continue;  // the reference percentile is quadratic
        SCOPED_TRACE(c.name);
        Options opt;
        opt.perPointDistances = true;
        Result<HausdorffResult> r = cpu::cpuHausdorff(c.a, c.b, opt);
        ASSERT_TRUE(r.ok());
        Result<HausdorffStats> s = hausdorffStats(*r, c.a, c.b, o);
        ASSERT_TRUE(s.ok()) << s.error().message;
        const std::vector<double>& da = r->aNearest.distance;
        const std::vector<double>& db = r->bNearest.distance;
        std::vector<double> pooled = da;
        pooled.insert(pooled.end(), db.begin(), db.end());
        expectStatsMatch(da, s->aToB, o);
        expectStatsMatch(db, s->bToA, o);
        expectStatsMatch(pooled, s->pooled, o);
        for (size_t i = 0; i < o.percentiles.size(); ++i) {
            const double p = o.percentiles[i];
            const double hd = std::max(referencePercentile(da, p), referencePercentile(db, p));
            EXPECT_EQ(s->symmetric[i].value, hd) << "p " << p;
            double byName = -1;
            ASSERT_TRUE(percentileVariant(*s, "max", p, byName));
            EXPECT_EQ(byName, hd);
            ASSERT_TRUE(percentileVariant(*s, "pooled", p, byName));
            EXPECT_EQ(byName, referencePercentile(pooled, p));
        }
        EXPECT_EQ(s->symmetric.back().value, r->hausdorff);  // HD100 = H
        EXPECT_EQ(s->aToB.histogram.hi, std::max(s->aToB.max, s->bToA.max) > 0 ? r->hausdorff : 1.0);
        glm::dvec3 lo(INFINITY), hi(-INFINITY);
        for (auto* set : {&c.a, &c.b}) {
            for (const glm::vec3& p : *set) {
                lo = glm::min(lo, glm::dvec3(p));
                hi = glm::max(hi, glm::dvec3(p));
            }
        }
        EXPECT_DOUBLE_EQ(s->diagonal,
                         std::sqrt((hi.x - lo.x) * (hi.x - lo.x) + (hi.y - lo.y) * (hi.y - lo.y) +
                                   (hi.z - lo.z) * (hi.z - lo.z)));
        ++checked;
    }
    EXPECT_GE(checked, 20u);
}

TEST(Stats, FixedRangeCountsOutside) {
    HausdorffResult r;
    r.aNearest.distance = {0.0, 0.5, 1.0, 2.0, 3.0};
    r.bNearest.distance = {-0.0};
    const std::vector<glm::vec3> a(5), b(1);
    StatsOptions o;
    o.histogramBins = 4;
    o.rangeLo = 0.5;
    o.rangeHi = 2.5;
    Result<HausdorffStats> s = hausdorffStats(r, a, b, o);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->aToB.histogram.below, 1u);
    EXPECT_EQ(s->aToB.histogram.above, 1u);
    EXPECT_EQ(s->aToB.histogram.counts, (std::vector<uint64_t>{1, 1, 0, 1}));
    EXPECT_EQ(s->pooled.histogram.below, 2u);
}

// A fixed range is finite and non-empty: (0, inf) gave infinite bins (NaN
// edges, every count in bin 0); NaN or an empty range fell back to auto.
// Both 0, the default, is the automatic range.
TEST(Stats, FixedRangeMustBeFiniteAndNonEmpty) {
    HausdorffResult r;
    r.aNearest.distance = {0.0, 0.5, 2.0};
    r.bNearest.distance = {1.0};
    const std::vector<glm::vec3> a(3), b(1);
    const double inf = std::numeric_limits<double>::infinity();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::pair<double, double> bad[] = {{0.0, inf}, {-inf, 1.0}, {nan, 1.0}, {0.0, nan},
                                             {0.5, 0.5}, {0.5, 0.1},  {-inf, inf}};
    for (const auto& [lo, hi] : bad) {
        StatsOptions o;
        o.rangeLo = lo;
        o.rangeHi = hi;
        Result<HausdorffStats> s = hausdorffStats(r, a, b, o);
        ASSERT_FALSE(s.ok()) << lo << " " << hi;
        EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(s.error().message.find("histogram range [rangeLo, rangeHi]"), std::string::npos)
            << s.error().message;
    }
    Result<HausdorffStats> automatic = hausdorffStats(r, a, b, StatsOptions{});
    ASSERT_TRUE(automatic.ok());
    EXPECT_EQ(automatic->aToB.histogram.lo, 0.0);
    EXPECT_EQ(automatic->aToB.histogram.hi, 2.0);
    StatsOptions below;  // a fixed range below 0 is a range: every distance above it
    below.rangeLo = -2.0;
    below.rangeHi = -1.0;
    Result<HausdorffStats> s = hausdorffStats(r, a, b, below);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->pooled.histogram.above, 4u);
}

TEST(Stats, MissingPerPointIsAnError) {
    HausdorffResult r;
    const std::vector<glm::vec3> a(3), b(2);
    Result<HausdorffStats> s = hausdorffStats(r, a, b);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
}

TEST(Stats, DirectedOnly) {
    HausdorffResult r;
    r.directedOnly = true;
    r.aNearest.distance = {1.0, 3.0};
    const std::vector<glm::vec3> a(2), b(7);
    Result<HausdorffStats> s = hausdorffStats(r, a, b);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->bToA.count, 0u);
    EXPECT_EQ(s->pooled.count, 0u);
    double v = 0;
    ASSERT_TRUE(percentileVariant(*s, "max", 95, v));
    EXPECT_EQ(v, 3.0);
    EXPECT_FALSE(percentileVariant(*s, "median-ish", 95, v));
}

}  // namespace
}  // namespace rthdist::test
