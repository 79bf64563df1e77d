// The reconstruction-evaluation summary (rthdist/eval.hpp) against an
// independent computation in the test: brute-force nearest distances over
// every pair (or every triangle: tests/common), sorted copies for the
// medians, plain loops for the rest; on a pair of a few thousand points
// (fixed, printed seed), with and without a cap, and a surface target.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "rthdist/eval.hpp"

namespace rthdist {
namespace {

std::vector<double> bruteNearest(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to) {
    std::vector<double> d(from.size());
    for (size_t i = 0; i < from.size(); ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (const glm::dvec3& t : to) best = std::min(best, glm::dot(from[i] - t, from[i] - t));
        d[i] = std::sqrt(best);
    }
    return d;
}

struct Expected {
    double mean = 0, median = 0, meanSquared = 0;
    size_t kept = 0;
};

Expected expected(const std::vector<double>& d, double cap) {
    std::vector<double> kept;
    for (double v : d)
        if (cap == 0.0 || v < cap) kept.push_back(v);
    std::sort(kept.begin(), kept.end());
    Expected e;
    e.kept = kept.size();
    for (double v : kept) {
        e.mean += v / double(kept.size());
        e.meanSquared += v * v / double(kept.size());
    }
    const size_t n = kept.size();
    e.median = n % 2 == 1 ? kept[n / 2] : (kept[n / 2 - 1] + kept[n / 2]) / 2.0;
    return e;
}

double below(const std::vector<double>& d, double tau) {
    size_t n = 0;
    for (double v : d) n += v < tau ? 1 : 0;
    return double(n) / double(d.size());
}

void expectSummary(const EvalSummary& s, const std::vector<double>& acc, const std::vector<double>& comp,
                   const EvalOptions& options) {
    const Expected a = expected(acc, options.cap), c = expected(comp, options.cap);
    EXPECT_EQ(s.accuracy.count, acc.size());
    EXPECT_EQ(s.accuracy.kept, a.kept);
    EXPECT_EQ(s.completeness.kept, c.kept);
    EXPECT_NEAR(s.accuracy.mean, a.mean, 1e-12 * a.mean);
    EXPECT_EQ(s.accuracy.median, a.median);
    EXPECT_NEAR(s.completeness.mean, c.mean, 1e-12 * c.mean);
    EXPECT_EQ(s.completeness.median, c.median);
    EXPECT_NEAR(s.chamferMeanOfMeans, (a.mean + c.mean) / 2, 1e-12 * a.mean);
    EXPECT_NEAR(s.chamferSumOfMeans, a.mean + c.mean, 1e-12 * a.mean);
    EXPECT_NEAR(s.chamferSumOfMeanSquares, a.meanSquared + c.meanSquared, 1e-12 * a.meanSquared);
    ASSERT_EQ(s.thresholds.size(), options.thresholds.size());
    for (size_t i = 0; i < options.thresholds.size(); ++i) {
        const double tau = options.thresholds[i], p = below(acc, tau), r = below(comp, tau);
        EXPECT_EQ(s.thresholds[i].threshold, tau);
        EXPECT_EQ(s.thresholds[i].precision, p);
        EXPECT_EQ(s.thresholds[i].recall, r);
        EXPECT_NEAR(s.thresholds[i].fscore, p + r > 0 ? 2 * p * r / (p + r) : 0.0, 1e-15);
    }
}

// A noisy sphere (the "reconstruction") and a clean one with a gap (the
// "ground truth"), a few thousand points each.
struct Pair {
    std::vector<glm::dvec3> recon, truth;
};

Pair spheres(uint64_t seed) {
    test::Rng rng(seed);
    Pair p;
    auto onSphere = [&](double noise) {
        glm::dvec3 v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        while (glm::dot(v, v) < 1e-3)
            v = glm::dvec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        return glm::normalize(v) * (1.0 + rng.uniform(-noise, noise));
    };
    for (int i = 0; i < 3000; ++i) p.recon.push_back(onSphere(0.05));
    for (int i = 0; i < 2500; ++i) {
        glm::dvec3 v = onSphere(0.0);
        if (v.z > 0.8) v.z += 0.5;  // a cap the reconstruction misses
        p.truth.push_back(v);
    }
    return p;
}

TEST(Eval, PointTargetsMatchTheIndependentComputation) {
    const uint64_t seed = 3480;
    std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
    const Pair p = spheres(seed);
    const std::vector<double> acc = bruteNearest(p.recon, p.truth), comp = bruteNearest(p.truth, p.recon);
    for (double cap : {0.0, 0.1}) {
        EvalOptions options;
        options.thresholds = {0.01, 0.05, 0.2};
        options.cap = cap;
        Options engine;
        engine.backend = Backend::kCpu;
        Result<EvalSummary> s = evaluatePoints(PointView(p.recon), PointView(p.truth), options, engine);
        ASSERT_TRUE(s) << s.error().message;
        std::printf("cap %g: accuracy %.6g completeness %.6g F@0.05 %.6g\n", cap, s->accuracy.mean,
                    s->completeness.mean, s->thresholds[1].fscore);
        expectSummary(*s, acc, comp, options);
        if (cap > 0.0) EXPECT_LT(s->completeness.kept, s->completeness.count);  // the missed cap is dropped
    }
}

TEST(Eval, SurfaceTargetMatchesTheBruteForceOverTriangles) {
    const test::SurfaceCase c = test::heightField(3481, 10, 5.0);
    test::Rng rng(3481);
    std::vector<glm::dvec3> recon;
    for (int i = 0; i < 2000; ++i)
        recon.emplace_back(rng.uniform(0, 5), rng.uniform(0, 5), rng.uniform(-1, 1));
    const oracle::SurfaceDirectedExact exact = oracle::bruteForceSurface(recon, c.vertices, c.indices);
    std::vector<double> acc;
    for (const oracle::SurfaceNearest& n : exact.perQuery) acc.push_back(std::sqrt(n.distance2));
    const std::vector<double> comp = bruteNearest(c.vertices, recon);  // every vertex is used
    EvalOptions options;
    options.thresholds = {0.1, 0.5};
    Result<EvalSummary> s =
        evaluateToSurface(PointView(recon), MeshView{PointView(c.vertices), c.indices}, options);
    ASSERT_TRUE(s) << s.error().message;
    expectSummary(*s, acc, comp, options);
}

TEST(Eval, EverythingCappedIsNaNNotZero) {
    const std::vector<double> acc{2, 3}, comp{4};
    EvalOptions options;
    options.cap = 1.0;
    options.thresholds = {5.0};
    Result<EvalSummary> s = evaluationSummary(acc, comp, options);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->accuracy.kept, 0u);
    EXPECT_TRUE(std::isnan(s->accuracy.mean));
    EXPECT_TRUE(std::isnan(s->chamferSumOfMeans));
    EXPECT_EQ(s->thresholds[0].fscore, 1.0);  // precision and recall ignore the cap
}

TEST(Eval, MedianOfAnEvenCountIsTheMeanOfTheMiddleTwo) {
    Result<EvalSummary> s = evaluationSummary(std::vector<double>{4, 1, 3, 2}, std::vector<double>{5}, {});
    ASSERT_TRUE(s);
    EXPECT_EQ(s->accuracy.median, 2.5);
    EXPECT_EQ(s->completeness.median, 5.0);
    EXPECT_EQ(s->accuracy.max, 4.0);
}

TEST(Eval, BadValuesAreErrorsNamingThem) {
    const std::vector<double> d{1.0};
    for (double t : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        EvalOptions options;
        options.thresholds = {0.5, t};
        Result<EvalSummary> s = evaluationSummary(d, d, options);
        ASSERT_FALSE(s);
        EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(s.error().message.find("evaluation threshold 1"), std::string::npos) << s.error().message;
    }
    EvalOptions options;
    options.cap = -1.0;
    EXPECT_FALSE(evaluationSummary(d, d, options));
    Result<EvalSummary> s = evaluationSummary(std::vector<double>{}, d, {});
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("accuracy"), std::string::npos);
}

}  // namespace
}  // namespace rthdist
