// Narrowed targets (src/api/narrowed_targets.hpp): issue 33's far-cluster
// family on the backend under test (RTHDIST_TEST_BACKEND) against the double
// brute force, values, witnesses and per-point nearest targets, and the
// narrowing itself on the host (NarrowTargets.*: no device).
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "api/narrowed_targets.hpp"
#include "api/route_planner.hpp"
#include "common/brute_force.hpp"
#include "core/index_space.hpp"
#include "engine_test_support.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {
namespace {

// n points uniform in a cube of `side` at the origin, then `strays` points
// 1-10 km away in random directions; a few of the cluster's points again at
// the end when n > 28 (duplicates: ties between target indices).
std::vector<glm::vec3> farCluster(size_t n, float side, size_t strays, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, side);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> r(1000.0, 10000.0);
    std::vector<glm::vec3> p(n);
    for (auto& v : p) v = glm::vec3(u(rng), u(rng), u(rng));
    for (size_t k = 0; k < strays; ++k) {
        glm::dvec3 d(g(rng), g(rng), g(rng));
        p.push_back(glm::vec3(glm::normalize(d) * r(rng)));
    }
    if (n > 28)
        for (size_t k = 0; k < 4; ++k) p.push_back(p[k * 7]);
    return p;
}

// Values and witnesses equal the brute force's (ties: smallest indices).
// Per-point entries (README "Precision"): the double distance of each
// query's float nearest pair, within 2e of the exact nearest distance, e =
// 2^-20 m, m the largest |coordinate| of the frame the direction was
// searched in: the whole pair's, or for a narrowed direction its own
// (`narrowedMagnitude`, 0: not narrowed).
void expectExact(const HausdorffResult& r, std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                 bool perPoint, double narrowedMagnitudeBToA = 0.0) {
    const oracle::DirectedExact ab = oracle::bruteForceDirected(a, b), ba = oracle::bruteForceDirected(b, a);
    EXPECT_EQ(r.aToB.distance, ab.distance);
    EXPECT_EQ(r.aToB.queryIndex, ab.queryIndex);
    EXPECT_EQ(r.aToB.targetIndex, ab.targetIndex);
    EXPECT_TRUE(r.aToB.certificate.confirmed);
    if (!r.directedOnly) {
        EXPECT_EQ(r.bToA.distance, ba.distance);
        EXPECT_EQ(r.bToA.queryIndex, ba.queryIndex);
        EXPECT_EQ(r.bToA.targetIndex, ba.targetIndex);
        EXPECT_TRUE(r.bToA.certificate.confirmed);
        EXPECT_EQ(r.hausdorff, std::max(ab.distance, ba.distance));
    }
    if (!perPoint) return;
    const core::Bounds boxA = core::boundsOf(a), boxB = core::boundsOf(b);
    const double whole = std::max(core::largestMagnitude(boxA), core::largestMagnitude(boxB));
    for (auto [got, q, t, m] :
         {std::tuple{&r.aNearest, a, b, whole},
          std::tuple{&r.bNearest, b, a, narrowedMagnitudeBToA > 0 ? narrowedMagnitudeBToA : whole}}) {
        if (got == &r.bNearest && r.directedOnly) continue;
        const double twoE = 2.0 * std::ldexp(m, -20);
        const std::vector<oracle::NearestExact> want = oracle::bruteForceNearestIndexed(q, t);
        ASSERT_EQ(got->nearest.size(), want.size());
        ASSERT_EQ(got->distance.size(), want.size());
        for (size_t i = 0; i < want.size(); ++i) {
            ASSERT_LT(got->nearest[i], t.size()) << "point " << i;
            const glm::dvec3 d = glm::dvec3(q[i]) - glm::dvec3(t[got->nearest[i]]);
            ASSERT_EQ(got->distance[i], std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z)) << "point " << i;
            ASSERT_GE(got->distance[i], want[i].distance) << "point " << i;
            ASSERT_LE(got->distance[i] - want[i].distance, twoE) << "point " << i;
        }
    }
}

// Strays in A only: B -> A narrows A to the cluster; A -> B keeps B whole.
TEST(NarrowedTargets, FarClusterWithStraysInOneSetMatchesTheBruteForce) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    for (float side : {1e-4f, 1e-3f, 1e-2f}) {
        SCOPED_TRACE(testing::Message() << "side " << side);
        const std::vector<glm::vec3> a = farCluster(3000, side, 5, 11), b = farCluster(2500, side, 0, 12);
        for (bool perPoint : {false, true}) {
            CallOptions call;
            call.perPointDistances = perPoint;
            Result<HausdorffResult> r = engine->compute(a, b, call);
            ASSERT_TRUE(r) << r.error().message;
            expectExact(*r, a, b, perPoint, 2.0 * side);  // B -> A: the clusters' own frame
            EXPECT_EQ(r->aToB.counters.narrowedTargets, 0u);
            EXPECT_EQ(r->bToA.counters.narrowedTargets, 3000u + 4u);  // A's cluster and its duplicates
        }
        // The other way round (strays in the second set), directed: A -> B narrows B.
        CallOptions directed;
        directed.directedOnly = true;
        Result<HausdorffResult> r = engine->compute(b, a, directed);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, b, a, false);
        EXPECT_EQ(r->aToB.counters.narrowedTargets, 3000u + 4u);
    }
}

// Double views take the same route (the narrowed copy keeps their precision).
TEST(NarrowedTargets, DoubleViewsOfAFarClusterMatchTheBruteForce) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> a = farCluster(2000, 1e-3f, 3, 21), b = farCluster(2000, 1e-3f, 0, 22);
    const std::vector<glm::dvec3> ad(a.begin(), a.end()), bd(b.begin(), b.end());
    Result<HausdorffResult> r = engine->compute(PointView(ad), PointView(bd));
    ASSERT_TRUE(r) << r.error().message;
    expectExact(*r, a, b, false);
    EXPECT_GT(r->bToA.counters.narrowedTargets, 0u);
}

// The same strays in both sets (each one's nearest is its twin, h is the
// clusters'): each direction sets its stray queries apart (against every
// target) and narrows the targets of the rest.
TEST(NarrowedTargets, CommonStraysAreSetApartAndTheRestNarrowed) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<glm::vec3> a = farCluster(3000, 1e-3f, 0, 61), b = farCluster(2800, 1e-3f, 0, 62);
    const std::vector<glm::vec3> common =
        farCluster(0, 1e-3f, 4, 63);                          // 4 strays (and no duplicates: none to copy)
    a.insert(a.begin() + 100, common.begin(), common.end());  // strays amid the cluster's indices
    b.insert(b.end(), common.begin(), common.end());
    for (bool perPoint : {false, true}) {
        CallOptions call;
        call.perPointDistances = perPoint;
        Result<HausdorffResult> r = engine->compute(a, b, call);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, perPoint);
        EXPECT_EQ(r->aToB.counters.narrowedTargets, 2800u + 4u);  // B's cluster and its duplicates
        EXPECT_EQ(r->bToA.counters.narrowedTargets, 3000u + 4u);
        EXPECT_EQ(r->aToB.counters.queries, a.size());  // the core's and the strays' calls together
    }
    CallOptions directed;
    directed.directedOnly = true;
    Result<HausdorffResult> r = engine->compute(a, b, directed);
    ASSERT_TRUE(r) << r.error().message;
    expectExact(*r, a, b, false);
    EXPECT_EQ(r->hausdorff, r->aToB.distance);
}

// Strays of their own in both sets: h is kilometres, far above the slack,
// so the whole search settles the clusters at once; nothing narrows.
TEST(NarrowedTargets, StraysInBothSetsSearchEveryTarget) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> a = farCluster(2000, 1e-3f, 3, 31), b = farCluster(2000, 1e-3f, 3, 32);
    Result<HausdorffResult> r = engine->compute(a, b);
    ASSERT_TRUE(r) << r.error().message;
    expectExact(*r, a, b, false);
    EXPECT_EQ(r->aToB.counters.narrowedTargets, 0u);
    EXPECT_EQ(r->bToA.counters.narrowedTargets, 0u);
}

// The narrowing alone (host): the kept targets are exactly those within R of
// Q's box, in input order, R bounds every query's nearest distance, and
// nothing narrows where no gain is possible.
TEST(NarrowTargets, KeepsEveryTargetWithinReachInOrder) {
    const std::vector<glm::vec3> q = farCluster(500, 1e-3f, 0, 41), t = farCluster(800, 1e-3f, 6, 42);
    const core::Bounds qBox = core::boundsOf(q), tBox = core::boundsOf(t);
    const std::optional<api::NarrowedTargets> n = api::narrowTargets(q, qBox, true, t, tBox, true, 2);
    ASSERT_TRUE(n);
    const std::vector<double> nearest = oracle::bruteForceNearest(q, t);
    EXPECT_GE(n->radius, *std::max_element(nearest.begin(), nearest.end()));
    std::vector<uint64_t> want;
    for (size_t i = 0; i < t.size(); ++i) {
        const glm::dvec3 p(t[i]);
        const glm::dvec3 d =
            glm::max(glm::max(glm::dvec3(qBox.lo) - p, p - glm::dvec3(qBox.hi)), glm::dvec3(0.0));
        if (std::sqrt(glm::dot(d, d)) <= n->radius) want.push_back(i);
    }
    EXPECT_EQ(n->targets.original, want);
    EXPECT_TRUE(n->strays.original.empty());
    ASSERT_EQ(n->targets.view.count, want.size());
    for (size_t k = 0; k < want.size(); ++k) EXPECT_EQ(n->targets.view.at(k), glm::dvec3(t[want[k]]));
    EXPECT_EQ(want.size(), 800u + 4u);  // the strays are dropped, the cluster kept
}

TEST(NarrowTargets, NothingNarrowsWithoutGain) {
    // Queries spanning the strays, or targets all within reach.
    const std::vector<glm::vec3> strays = farCluster(500, 1e-3f, 6, 51),
                                 cluster = farCluster(500, 1e-3f, 0, 52);
    EXPECT_FALSE(
        api::narrowTargets(strays, core::boundsOf(strays), true, cluster, core::boundsOf(cluster), true, 2));
    EXPECT_FALSE(api::narrowTargets(cluster, core::boundsOf(cluster), true, cluster, core::boundsOf(cluster),
                                    true, 2));
    // A cluster far from the origin in float32 coordinates: the frame keeps
    // the origin, so the narrowed magnitude is no smaller.
    std::vector<glm::vec3> shifted = cluster;
    for (auto& p : shifted) p += glm::vec3(5000.0f, 0.0f, 0.0f);
    std::vector<glm::vec3> withStrays = shifted;
    withStrays.push_back(glm::vec3(-5000.0f, 0.0f, 0.0f));
    EXPECT_FALSE(api::narrowTargets(shifted, core::boundsOf(shifted), true, withStrays,
                                    core::boundsOf(withStrays), true, 2));
    // The same in double coordinates: the frame's origin moves to the box, so it narrows.
    EXPECT_TRUE(api::narrowTargets(shifted, core::boundsOf(shifted), false, withStrays,
                                   core::boundsOf(withStrays), false, 2));
}

TEST(NarrowTargets, GainThreshold) {
    EXPECT_TRUE(api::narrowingPays(256.0, 1.0));
    EXPECT_FALSE(api::narrowingPays(255.0, 1.0));
}

}  // namespace
}  // namespace rthdist
