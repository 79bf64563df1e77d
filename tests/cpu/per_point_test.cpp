// Per-point nearest distances of the CPU backend (Options::perPointDistances)
// against the double brute force, for every point of every oracle case, plus
// the progress callback's contract.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "common/brute_force.hpp"
#include "common/oracle_cases.hpp"
#include "common/per_point_floor_check.hpp"
#include "cpu/cpu_hausdorff.hpp"

namespace rthdist::test {
namespace {

const std::vector<OracleCase>& cases() {
    static const std::vector<OracleCase> all = makeOracleCases();
    return all;
}

HausdorffResult runPerPoint(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                            Options options = {}) {
    options.backend = Backend::kCpu;
    options.perPointDistances = true;
    Result<HausdorffResult> r = cpu::cpuHausdorff(a, b, options);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? r.value() : HausdorffResult{};
}

double pairDistance(const glm::vec3& p, const glm::vec3& q) {
    const double dx = double(p.x) - double(q.x), dy = double(p.y) - double(q.y),
                 dz = double(p.z) - double(q.z);
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Every query: the same NN index as the brute force gives the same double;
// another index (a tie, or a float-rounding near tie) is within tolerance.
// Returns how many queries picked another index than the brute force.
size_t expectNearestMatches(const std::vector<glm::vec3>& queries, const std::vector<glm::vec3>& targets,
                            const PerPoint& got, double tolerance, const char* direction) {
    SCOPED_TRACE(direction);
    const std::vector<oracle::NearestExact> want = oracle::bruteForceNearestIndexed(queries, targets);
    EXPECT_EQ(got.distance.size(), queries.size());
    EXPECT_EQ(got.nearest.size(), queries.size());
    if (got.distance.size() != queries.size() || got.nearest.size() != queries.size()) return 0;
    size_t otherIndex = 0, failures = 0;
    for (size_t i = 0; i < queries.size() && failures < 5; ++i) {
        const uint32_t j = got.nearest[i];
        if (j >= targets.size()) {
            ADD_FAILURE() << "query " << i << ": nearest index " << j << " out of range";
            ++failures;
            continue;
        }
        if (got.distance[i] != pairDistance(queries[i], targets[j])) {
            ADD_FAILURE() << "query " << i << ": distance not recomputed from its pair";
            ++failures;
        }
        if (j == want[i].targetIndex) {
            if (got.distance[i] != want[i].distance) {
                ADD_FAILURE() << "query " << i << ": " << got.distance[i] << " != brute force "
                              << want[i].distance;
                ++failures;
            }
        } else {
            ++otherIndex;
            if (!(std::fabs(got.distance[i] - want[i].distance) <= tolerance)) {
                ADD_FAILURE() << "query " << i << ": nearest " << j << " (" << got.distance[i]
                              << ") vs brute force " << want[i].targetIndex << " (" << want[i].distance
                              << "), tolerance " << tolerance;
                ++failures;
            }
        }
    }
    return otherIndex;
}

class CpuPerPoint : public ::testing::TestWithParam<size_t> {};

TEST_P(CpuPerPoint, EveryPointMatchesBruteForce) {
    const OracleCase& c = cases()[GetParam()];
    SCOPED_TRACE(c.name + " seed " + std::to_string(c.seed));
    const HausdorffResult r = runPerPoint(c.a, c.b);
    expectMatchesOracle(c, r);
    const double tolerance = oracleTolerance(c.a, c.b, r.hausdorff);
    const size_t otherAB = expectNearestMatches(c.a, c.b, r.aNearest, tolerance, "A->B");
    const size_t otherBA = expectNearestMatches(c.b, c.a, r.bNearest, tolerance, "B->A");
    if (otherAB + otherBA > 0) {
        std::printf("[ info ] %s: %zu + %zu queries chose another (equally near within tolerance) index\n",
                    c.name.c_str(), otherAB, otherBA);
    }
    // The witnesses are the per-point maxima (first index among ties).
    for (auto [d, pp] : {std::pair{&r.aToB, &r.aNearest}, std::pair{&r.bToA, &r.bNearest}}) {
        if (pp->distance.empty()) continue;
        size_t arg = 0;
        for (size_t i = 1; i < pp->distance.size(); ++i) {
            if (pp->distance[i] > pp->distance[arg]) arg = i;
        }
        EXPECT_EQ(d->queryIndex, arg);
        EXPECT_EQ(d->targetIndex, pp->nearest[arg]);
        EXPECT_EQ(d->distance, pp->distance[arg]);
    }
    EXPECT_EQ(r.hausdorff, std::max(r.aToB.distance, r.bToA.distance));
}

INSTANTIATE_TEST_SUITE_P(Cases, CpuPerPoint, ::testing::Range<size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                             return cases()[info.param].name;
                         });

// Voxel-like lattices (masks' boundaries): every coordinate a multiple of a
// power of two, so every float squared distance is exact and ties are real.
// Each query's nearest must be at the smallest distance and, among the
// targets at that distance, the one with the smallest input index, however
// the search reached it (grid cells around the query or the BVH).
TEST(CpuPerPointLattice, TiesPickTheSmallestIndex) {
    std::mt19937 rng(5);
    for (const glm::vec3 spacing :
         {glm::vec3(1.0f), glm::vec3(0.5f, 0.5f, 2.0f), glm::vec3(0.25f, 1.0f, 4.0f)}) {
        for (int trial = 0; trial < 4; ++trial) {
            std::vector<glm::vec3> a, b;
            const int side = 6 + 10 * trial;
            for (int k = 0; k < side; ++k)
                for (int j = 0; j < side; ++j)
                    for (int i = 0; i < side; ++i) {
                        const glm::vec3 p = glm::vec3(float(i), float(j), float(k)) * spacing;
                        const unsigned roll = rng() % 100;
                        if (roll < 6) a.push_back(p);
                        if (roll >= 3 && roll < 10) b.push_back(p);
                    }
            std::shuffle(b.begin(), b.end(), rng);
            const HausdorffResult r = runPerPoint(a, b);
            ASSERT_EQ(r.aNearest.nearest.size(), a.size());
            size_t failures = 0;
            for (size_t i = 0; i < a.size() && failures < 5; ++i) {
                double best = INFINITY;
                uint32_t bestIndex = 0;
                for (size_t j = 0; j < b.size(); ++j) {
                    const double d = pairDistance(a[i], b[j]);
                    if (d < best) best = d, bestIndex = uint32_t(j);
                }
                if (r.aNearest.nearest[i] != bestIndex || r.aNearest.distance[i] != best) {
                    ADD_FAILURE() << "spacing " << spacing.x << "," << spacing.y << "," << spacing.z
                                  << " side " << side << " query " << i << ": nearest "
                                  << r.aNearest.nearest[i] << " at " << r.aNearest.distance[i] << ", want "
                                  << bestIndex << " at " << best;
                    ++failures;
                }
            }
        }
    }
}

// A per-point call with a floor (core/per_point_floor.hpp: the pieces'
// round one), both directions at the median nearest distance: a query stops
// below its floor only where its nearest lies below it, and comes back
// with its exact nearest otherwise, in the list of those above the floor
// (every direction with a floor handed back sparse); without a floor none
// stops.
TEST(CpuPerPointFloor, StopsOnlyQueriesBelowIt) {
    const std::vector<OracleCase>& all = cases();
    size_t below = 0, run = 0, sparse = 0, withFloor = 0;
    for (size_t i = 0; i < all.size(); i += 3) {
        const OracleCase& c = all[i];
        if (c.a.size() * c.b.size() > 40000000 || c.a.size() + c.b.size() < 8) continue;
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        const double scale = searchScale(c.a, c.b);
        const CaseNearest nearest(c);
        const core::PerPointFloor floor = medianFloors(nearest, scale);
        Options options;
        options.perPointDistances = true;
        auto r = cpu::cpuHausdorff(c.a, c.b, scale, options, floor);
        ASSERT_TRUE(r.ok()) << r.error().message;
        withFloor += (floor.kill2(0) > 0.0f ? 1 : 0) + (floor.kill2(1) > 0.0f ? 1 : 0);
        below += expectFloorHolds(c, nearest, *r, floor, scale, &sparse);
        auto whole = cpu::cpuHausdorff(c.a, c.b, scale, options);
        ASSERT_TRUE(whole.ok()) << whole.error().message;
        EXPECT_EQ(expectFloorHolds(c, nearest, *whole, floor, scale), 0u);
        ++run;
    }
    EXPECT_GT(run, 50u);
    EXPECT_GT(below, 1000u);  // the floor stops queries
    EXPECT_EQ(sparse, withFloor);
}

TEST(CpuPerPointOptions, OffLeavesArraysEmpty) {
    const std::vector<glm::vec3> a{{0, 0, 0}, {1, 0, 0}}, b{{0, 0, 0}};
    Result<HausdorffResult> r = cpu::cpuHausdorff(a, b, Options{});
    ASSERT_TRUE(r.ok());
    EXPECT_TRUE(r->aNearest.distance.empty());
    EXPECT_TRUE(r->bNearest.nearest.empty());
}

TEST(CpuPerPointOptions, DirectedOnlyFillsOneSide) {
    const std::vector<glm::vec3> a{{0, 0, 0}, {1, 0, 0}}, b{{0, 0, 0}};
    Options o;
    o.directedOnly = true;
    const HausdorffResult r = runPerPoint(a, b, o);
    ASSERT_EQ(r.aNearest.distance.size(), 2u);
    EXPECT_EQ(r.aNearest.distance[0], 0.0);
    EXPECT_EQ(r.aNearest.distance[1], 1.0);
    EXPECT_TRUE(r.bNearest.distance.empty());
    EXPECT_EQ(r.hausdorff, 1.0);
}

TEST(CpuPerPointOptions, ThreadCountDoesNotChangeAnything) {
    const OracleCase& c = cases().back();
    Options one;
    one.threads = 1;
    Options four;
    four.threads = 4;
    const HausdorffResult r1 = runPerPoint(c.a, c.b, one), r4 = runPerPoint(c.a, c.b, four);
    EXPECT_EQ(r1.aNearest.distance, r4.aNearest.distance);
    EXPECT_EQ(r1.aNearest.nearest, r4.aNearest.nearest);
    EXPECT_EQ(r1.bNearest.distance, r4.bNearest.distance);
    EXPECT_EQ(r1.bNearest.nearest, r4.bNearest.nearest);
    EXPECT_EQ(r1.hausdorff, r4.hausdorff);
}

// Progress: named stages, fractions in [0, 1] that never decrease, ending at 1,
// all from the calling thread; with and without per-point distances.
TEST(CpuProgress, MonotoneFromCallingThreadEndsAtOne) {
    const OracleCase& c = cases().back();
    for (bool perPoint : {false, true}) {
        SCOPED_TRACE(perPoint ? "per-point" : "maximum only");
        std::vector<std::pair<std::string, double>> calls;
        const std::thread::id caller = std::this_thread::get_id();
        bool otherThread = false;
        Options o;
        o.perPointDistances = perPoint;
        o.threads = 2;
        o.progress = [&](const char* stage, double fraction) {
            calls.emplace_back(stage, fraction);
            if (std::this_thread::get_id() != caller) otherThread = true;
        };
        Result<HausdorffResult> r = cpu::cpuHausdorff(c.a, c.b, o);
        ASSERT_TRUE(r.ok());
        EXPECT_FALSE(otherThread);
        ASSERT_GE(calls.size(), 4u);
        for (size_t i = 0; i < calls.size(); ++i) {
            const std::string& s = calls[i].first;
            EXPECT_TRUE(s == "index" || s == "cull" || s == "search" || s == "refine") << s;
            EXPECT_GE(calls[i].second, 0.0);
            EXPECT_LE(calls[i].second, 1.0);
            if (i > 0) EXPECT_GE(calls[i].second, calls[i - 1].second) << i;
        }
        EXPECT_EQ(calls.back().second, 1.0);
    }
}

}  // namespace
}  // namespace rthdist::test
