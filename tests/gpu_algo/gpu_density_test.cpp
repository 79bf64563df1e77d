// Issue 17 on the GPU backend named by RTHDIST_TEST_BACKEND: the density
// cases (tests/common/density_cases) against their exact reference, symmetric,
// directed and per-point, with the validation layer silent; and the leaf split
// of crowded cells seen in the counters.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <cstdio>

#include "common/case_sample.hpp"
#include "common/density_cases.hpp"
#include "common/rng.hpp"
#include "gpu_test_support.hpp"

namespace rthdist::test {
namespace {

TEST(GpuDensity, EveryCaseMatchesItsReference) {
    Options options = gpuOptions();
    RTHDIST_REQUIRE_ENGINE(engine, options);
    Options perPoint = options;
    perPoint.perPointDistances = true;
    auto perPointEngine = Engine::create(perPoint);
    ASSERT_TRUE(perPointEngine) << perPointEngine.error().message;
    for (const OracleCase& c : sampledCases(makeDensityCases())) {
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        const DensityReference ref = densityReference(c);
        auto r = engine->compute(c.a, c.b);
        ASSERT_TRUE(r.ok()) << r.error().message;
        std::printf("  %-28s %7zu x %-7zu H %.9g  %.0f ms, cells %llu/%llu, iterations %u/%u\n",
                    c.name.c_str(), c.a.size(), c.b.size(), r->hausdorff, r->timings.total,
                    static_cast<unsigned long long>(r->aToB.counters.occupiedCells),
                    static_cast<unsigned long long>(r->bToA.counters.occupiedCells),
                    r->aToB.counters.iterations, r->bToA.counters.iterations);
        expectMatchesDensity(c, ref, *r);
        EXPECT_EQ(r->validationMessages, 0u);
        auto p = perPointEngine->compute(c.a, c.b);
        ASSERT_TRUE(p.ok()) << p.error().message;
        expectMatchesDensity(c, ref, *p);
        expectPerPointMatchesDensity(c, ref, *p);
        EXPECT_EQ(p->validationMessages, 0u);
    }
}

// A cluster of n points in a 1e-3 cube and one point 1000 away in each set:
// the grid over the box puts the whole cluster into one cell, which the index
// must cut into leaves of a few points (without the split the cells would be
// 2 per set). Exact against the brute force.
TEST(GpuDensity, CrowdedCellIsCutIntoLeaves) {
    Options options = gpuOptions();
    RTHDIST_REQUIRE_ENGINE(engine, options);
    Rng rng(17017);
    auto cluster = [&](int n) {
        std::vector<glm::vec3> p;
        for (int i = 0; i < n; ++i)
            p.emplace_back(glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-3);
        return p;
    };
    std::vector<glm::vec3> a = cluster(6000), b = cluster(5000);
    a.emplace_back(1000.0f, 1000.0f, 1000.0f);
    b.emplace_back(1000.0f, 999.0f, 1000.0f);
    const OracleCase c{"cluster_plus_far_point", 17017, a, b};
    auto r = engine->compute(c.a, c.b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectMatchesOracle(c, *r);
    EXPECT_GT(r->aToB.counters.occupiedCells, 5000u / 64u);
    EXPECT_GT(r->bToA.counters.occupiedCells, 6000u / 64u);
    EXPECT_EQ(r->validationMessages, 0u);
}

// Both sets crowded, one needing more split rounds than the other (a
// cluster inside a cluster 10^4 times smaller), and then one set crowded
// alone, first as A and then as B: the sets split side by side (each on its
// own counters and scratch, the one that is done sitting out the other's
// rounds) or alone. Exact against the brute force.
TEST(GpuDensity, SetsSplitSideBySideInRoundsOfTheirOwn) {
    Options options = gpuOptions();
    RTHDIST_REQUIRE_ENGINE(engine, options);
    Rng rng(18018);
    auto cube = [&](std::vector<glm::vec3>& p, int n, glm::dvec3 at, double edge) {
        for (int i = 0; i < n; ++i)
            p.emplace_back(at + glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform()) * edge);
    };
    std::vector<glm::vec3> nested, plain, sparse;
    cube(nested, 6000, glm::dvec3(0.0), 1e-3);
    cube(nested, 4000, glm::dvec3(5e-4), 1e-7);
    nested.emplace_back(1000.0f, 1000.0f, 1000.0f);
    cube(plain, 5000, glm::dvec3(0.0), 1e-3);
    plain.emplace_back(1000.0f, 999.0f, 1000.0f);
    cube(sparse, 3000, glm::dvec3(0.0), 1000.0);
    const OracleCase cases[] = {{"nested_and_plain_clusters", 18018, nested, plain},
                                {"crowded_a_alone", 18018, nested, sparse},
                                {"crowded_b_alone", 18018, sparse, plain}};
    for (const OracleCase& c : cases) {
        SCOPED_TRACE(c.name);
        auto r = engine->compute(c.a, c.b);
        ASSERT_TRUE(r.ok()) << r.error().message;
        expectMatchesOracle(c, *r);
        EXPECT_EQ(r->validationMessages, 0u);
    }
}

}  // namespace
}  // namespace rthdist::test
