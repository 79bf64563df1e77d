// The oracle suite on the GPU backend named by RTHDIST_TEST_BACKEND: every
// case of makeOracleCases() against the double brute force, with the
// validation layer on and required silent.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "common/brute_force.hpp"
#include "common/case_sample.hpp"
#include "common/geo_cases.hpp"
#include "common/oracle_cases.hpp"
#include "common/per_point_floor_check.hpp"
#include "gpu_algo/gpu_context_support.hpp"
#include "gpu_algo/gpu_hausdorff.hpp"
#include "gpu_algo/workspace.hpp"
#include "gpu_test_support.hpp"

namespace rthdist::test {
namespace {

TEST(GpuOracle, EveryCaseMatchesBruteForce) {
    Options options = gpuOptions();
    RTHDIST_REQUIRE_ENGINE(engine, options);
    const std::vector<OracleCase> cases = makeOracleCases();
    ASSERT_GE(cases.size(), 300u);
    std::printf("backend %s on %s: %zu oracle cases\n", backendName(engine->backend()),
                engine->deviceName().c_str(), cases.size());
    uint64_t lastMessages = 0;
    for (const OracleCase& c : sampledCases(cases)) {
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        auto r = engine->compute(c.a, c.b);
        ASSERT_TRUE(r.ok()) << r.error().message;
        // The seed of every case is printed, so a failure reproduces by name.
        std::printf("  %-24s seed %-20llu %6zu x %-6zu H %.9g  %.0f ms, iterations %u/%u\n", c.name.c_str(),
                    static_cast<unsigned long long>(c.seed), c.a.size(), c.b.size(), r->hausdorff,
                    r->timings.total, r->aToB.counters.iterations, r->bToA.counters.iterations);
        EXPECT_EQ(r->backend, options.backend);
        expectMatchesOracle(c, *r);
        EXPECT_EQ(r->validationMessages, lastMessages) << "validation layer reported messages";
        lastMessages = r->validationMessages;
    }
}

TEST(GpuOracle, DirectedOnlyAndFixedBits) {
    const std::vector<OracleCase> cases = makeOracleCases();
    for (int bits : {1, 4, 6}) {
        Options options = gpuOptions();
        options.bits = bits;
        options.directedOnly = bits == 4;
        RTHDIST_REQUIRE_ENGINE(engine, options);
        for (size_t i = 0; i < cases.size(); i += 7) {
            const OracleCase& c = cases[i];
            SCOPED_TRACE("bits " + std::to_string(bits) + " case " + c.name + " seed " +
                         std::to_string(c.seed));
            auto r = engine->compute(c.a, c.b);
            ASSERT_TRUE(r.ok()) << r.error().message;
            expectMatchesOracle(c, *r, options.directedOnly);
            EXPECT_EQ(r->aToB.counters.bits, uint32_t(bits));
            EXPECT_EQ(r->validationMessages, 0u);
        }
    }
}

}  // namespace
}  // namespace rthdist::test

namespace rthdist::test {
namespace {

// Per-point nearest distances (no early break) against the brute force, for
// every point of every oracle case.
TEST(GpuOracle, PerPointDistancesMatchBruteForce) {
    Options options = gpuOptions();
    options.perPointDistances = true;
    RTHDIST_REQUIRE_ENGINE(engine, options);
    const std::vector<OracleCase> cases = sampledCases(makeOracleCases());
    for (size_t i = 0; i < cases.size(); ++i) {
        const OracleCase& c = cases[i];
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        auto r = engine->compute(c.a, c.b);
        ASSERT_TRUE(r.ok()) << r.error().message;
        expectMatchesOracle(c, *r);
        const double tol = oracleTolerance(c.a, c.b, r->hausdorff);
        for (int dir = 0; dir < 2; ++dir) {
            const auto& q = dir == 0 ? c.a : c.b;
            const auto& t = dir == 0 ? c.b : c.a;
            const PerPoint& pp = dir == 0 ? r->aNearest : r->bNearest;
            ASSERT_EQ(pp.distance.size(), q.size());
            ASSERT_EQ(pp.nearest.size(), q.size());
            const std::vector<double> ref = oracle::bruteForceNearest(q, t);
            size_t bad = 0;
            for (size_t k = 0; k < q.size(); ++k) {
                const double d = glm::length(glm::dvec3(q[k]) - glm::dvec3(t[pp.nearest[k]]));
                if (std::abs(pp.distance[k] - ref[k]) > tol || d != pp.distance[k]) ++bad;
            }
            EXPECT_EQ(bad, 0u) << "direction " << dir;
        }
        EXPECT_EQ(r->validationMessages, 0u);
    }
}

// A per-point call with a floor (core/per_point_floor.hpp: the pieces'
// round one), both directions at the median nearest distance: every query
// stops below its floor only where its nearest lies below it, and comes back
// with its exact nearest otherwise, in the sparse list of those above the
// floor or, past the list's capacity, in the dense array; without a floor
// none stops.
TEST(GpuOracle, PerPointFloorStopsOnlyQueriesBelowIt) {
    RTHDIST_REQUIRE_CONTEXT(ctx);
    auto engine = gpu_algo::GpuHausdorff::create(*ctx, "", 0, *gpuOptions().tuning);
    ASSERT_TRUE(engine) << engine.error().message;
    CallOptions options;
    options.perPointDistances = true;
    options.perPointNearestOnly = true;
    const std::vector<OracleCase> cases = makeOracleCases();
    size_t below = 0, run = 0, sparse[2] = {0, 0}, withFloor = 0;
    for (size_t i = 0; i < cases.size(); i += 5) {
        const OracleCase& c = cases[i];
        if (c.a.size() * c.b.size() > 40000000 || c.a.size() + c.b.size() < 8) continue;
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        const double scale = searchScale(c.a, c.b);
        const CaseNearest nearest(c);
        const core::PerPointFloor floor = medianFloors(nearest, scale);
        withFloor += (floor.kill2(0) > 0.0f ? 1 : 0) + (floor.kill2(1) > 0.0f ? 1 : 0);
        // The queries above the floor handed back sparse, then (a list of
        // 3 at most) the dense read-back where more are above it.
        for (const uint32_t capacity : {gpu_algo::kAboveFloorCapacity, 3u}) {
            (*engine)->setAboveFloorCapacity(capacity);
            auto r = (*engine)->computeIndexed(c.a, c.b, scale, options, floor);
            ASSERT_TRUE(r) << r.error().message;
            below += expectFloorHolds(c, nearest, *r, floor, scale, &sparse[capacity == 3u ? 1 : 0]);
        }
        auto whole = (*engine)->computeIndexed(c.a, c.b, scale, options);
        ASSERT_TRUE(whole) << whole.error().message;
        EXPECT_EQ(whole->aboveFloor, nullptr);
        EXPECT_EQ(expectFloorHolds(c, nearest, *whole, floor, scale), 0u);
        ++run;
    }
    EXPECT_GT(run, 30u);
    EXPECT_EQ(sparse[0], withFloor);      // every direction with a floor handed back sparse
    EXPECT_LT(sparse[1], withFloor / 2);  // most read back dense past a list of 3
    EXPECT_GT(sparse[1], 0u);
    EXPECT_GT(below, 1000u);  // the floor stops queries
    EXPECT_EQ(ctx->validationMessageCount(), 0u);
}

}  // namespace
// Issue 10: double coordinates far from the origin (UTM, Earth-centred),
// against the double brute force on the backend under test.
TEST(GpuOracle, GeoreferencedDoublesMatchTheDoubleBruteForce) {
    Options options = gpuOptions();
    RTHDIST_REQUIRE_ENGINE(engine, options);
    for (const GeoCase& c : makeGeoCases()) {
        auto r = engine->compute(c.a, c.b);
        ASSERT_TRUE(r) << c.name << ": " << r.error().message;
        expectMatchesGeoOracle(c, *r);
    }
    EXPECT_EQ(engine->compute(makeGeoCases()[0].a, makeGeoCases()[0].b)->validationMessages, 0u);
}

}  // namespace rthdist::test
