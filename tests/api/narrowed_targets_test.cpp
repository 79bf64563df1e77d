// Narrowed targets (src/api/narrowed_targets.hpp): issue 33's far-cluster
// family on the backend under test (RTHDIST_TEST_BACKEND) against the double
// brute force, values, witnesses and per-point nearest targets, and the
// narrowing itself on the host (NarrowTargets.*: no device).
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
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

// How the pair narrows on the host (api::narrowPair over the sets' own
// boxes): nullopt, one call on both cores (joint) or directions apart.
std::optional<api::PairNarrowing> narrowing(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                            bool directedOnly = false, bool perPoint = false) {
    return api::narrowPair(a, core::SetSummary{core::boundsOf(a), true}, b,
                           core::SetSummary{core::boundsOf(b), true}, directedOnly, 2, perPoint);
}

// Strays of their own in both sets: h is kilometres, far above the slack,
// so the whole search settles the clusters at once; nothing narrows (found
// from both sets' splits, without a pass over the other set).
// On the GPU backends (BackendCaps::coresForOwnStrays) the cores run
// jointly instead: their whole search of such a pair left the clusters'
// queries uncut.
TEST(NarrowedTargets, StraysInBothSetsSearchEveryTarget) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> a = farCluster(2000, 1e-3f, 3, 31), b = farCluster(2000, 1e-3f, 3, 32);
    EXPECT_FALSE(narrowing(a, b));
    const std::optional<api::PairNarrowing> cores = narrowing(a, b, false, true);
    ASSERT_TRUE(cores && cores->joint);
    Result<HausdorffResult> r = engine->compute(a, b);
    ASSERT_TRUE(r) << r.error().message;
    expectExact(*r, a, b, false);
    const uint64_t kept = test::backendUnderTest() == Backend::kCpu ? 0u : 2000u + 4u;
    EXPECT_EQ(r->aToB.counters.narrowedTargets, kept);
    EXPECT_EQ(r->bToA.counters.narrowedTargets, kept);
}

// The same pair with per-point output: every query's nearest is wanted,
// not h alone, so the cores are searched jointly in their own frame (the
// strays' stretched it ~10^6-fold) and the strays against every target.
TEST(NarrowedTargets, PerPointCallsSearchTheCoresOfStraysOfTheirOwn) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> a = farCluster(2000, 1e-3f, 3, 31), b = farCluster(2000, 1e-3f, 3, 32);
    const std::optional<api::PairNarrowing> n = narrowing(a, b, false, true);
    ASSERT_TRUE(n && n->joint);
    for (const bool directed : {false, true}) {
        CallOptions call;
        call.perPointDistances = true;
        call.directedOnly = directed;
        Result<HausdorffResult> r = engine->compute(a, b, call);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, true);
        EXPECT_EQ(r->aToB.counters.narrowedTargets, 2000u + 4u);  // B's cluster and its duplicates
        if (!directed) EXPECT_EQ(r->bToA.counters.narrowedTargets, 2000u + 4u);
    }
}

// Each set's box reaches kilometres past the other's (A's far stray on x,
// B's on y): both directed values are far above the slack, so the pair is
// searched whole, decided from the boxes before any pass over the points,
// although A's first stray lies a few millimetres from B's cluster (whose
// test alone, the first stray against the other set, narrowed A -> B).
TEST(NarrowedTargets, BoxesReachingPastEachOtherLeaveThePairWhole) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<glm::vec3> a = farCluster(2000, 1e-3f, 0, 91), b = farCluster(2100, 1e-3f, 0, 92);
    a.push_back(glm::vec3(5e-3f));
    a.push_back(glm::vec3(5000.0f, 0.0f, 0.0f));
    b.push_back(glm::vec3(0.0f, -5000.0f, 0.0f));
    EXPECT_FALSE(narrowing(a, b));
    EXPECT_FALSE(narrowing(a, b, true));
    const bool gpu = test::backendUnderTest() != Backend::kCpu;  // BackendCaps::coresForOwnStrays
    for (bool directed : {false, true}) {
        CallOptions call;
        call.directedOnly = directed;
        Result<HausdorffResult> r = engine->compute(a, b, call);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, false);
        if (gpu) {
            const std::optional<api::PairNarrowing> cores = narrowing(a, b, directed, true);
            EXPECT_EQ(r->aToB.counters.narrowedTargets > 0u, cores.has_value());
            continue;
        }
        EXPECT_EQ(r->aToB.counters.narrowedTargets, 0u);
    }
}

// The joint call with strays in one set (of their own: B -> A narrows,
// A's strays go to the brute force) and in both (common ones), and
// directed (A's strays of their own: nothing narrows): the host's choice,
// then the values, witnesses and per-point entries against the brute force.
TEST(NarrowedTargets, OneCallOnTheCoresWithStraysInOneSetOrBoth) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> one = farCluster(2500, 1e-3f, 4, 71),
                                 cluster = farCluster(2400, 1e-3f, 0, 72);
    std::vector<glm::vec3> common = farCluster(2300, 1e-3f, 0, 73);
    const std::vector<glm::vec3> far = farCluster(0, 1e-3f, 2, 74);
    common.insert(common.begin(), far.begin(), far.end());  // strays first, last: the core is a run
    std::vector<glm::vec3> withFar = cluster;               // of the set (amid them: CommonStrays...)
    withFar.insert(withFar.end(), far.begin(), far.end());
    for (auto [a, b, directedJoint] : {std::tuple{one, cluster, false}, std::tuple{cluster, one, true},
                                       std::tuple{common, withFar, true}}) {
        SCOPED_TRACE(testing::Message() << a.size() << " x " << b.size());
        ASSERT_TRUE(narrowing(a, b) && narrowing(a, b)->joint);
        CallOptions perPoint;
        perPoint.perPointDistances = true;
        Result<HausdorffResult> r = engine->compute(a, b, perPoint);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, true);
        CallOptions directed;
        directed.directedOnly = true;
        EXPECT_EQ(narrowing(a, b, true) && narrowing(a, b, true)->joint, directedJoint);
        EXPECT_EQ(narrowing(a, b, true).has_value(), directedJoint);
        r = engine->compute(a, b, directed);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, false);
        EXPECT_TRUE(r->directedOnly);
    }
}

// Strays of B near A's core (within its reach, outside B's own sampled core):
// they can be A's nearest targets, so the directions run apart (each its
// own kept targets, B's strays among A's) and still match the brute force.
TEST(NarrowedTargets, StraysWithinTheOtherCoresReachRunTheDirectionsApart) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<glm::vec3> a = farCluster(3000, 1e-2f, 0, 81);  // a 10 mm cube
    std::vector<glm::vec3> b = farCluster(2000, 1e-3f, 0, 82);  // a 1 mm cube ...
    for (auto& p : b) p += glm::vec3(4.5e-3f);                  // ... at its centre
    for (glm::vec3 near : {glm::vec3(1e-3f), glm::vec3(9e-3f), glm::vec3(1e-3f, 9e-3f, 5e-3f)})
        b.push_back(near);                     // B's strays within A's cube
    const glm::vec3 far(1700.0f, 0.0f, 0.0f);  // and a common far point
    a.push_back(far);
    b.push_back(far);
    const std::optional<api::PairNarrowing> n = narrowing(a, b);
    ASSERT_TRUE(n);
    EXPECT_FALSE(n->joint);
    ASSERT_TRUE(n->targetsA && n->targetsB);
    EXPECT_EQ(n->targetsB->strays.view.count, 1u);  // A's far point
    EXPECT_EQ(n->targetsA->strays.view.count, 4u);  // B's near ones and the far point
    for (bool perPoint : {false, true}) {
        CallOptions call;
        call.perPointDistances = perPoint;
        Result<HausdorffResult> r = engine->compute(a, b, call);
        ASSERT_TRUE(r) << r.error().message;
        expectExact(*r, a, b, perPoint);
        EXPECT_EQ(r->aToB.counters.narrowedTargets, b.size() - 1);  // B but the far point
        EXPECT_GT(r->bToA.counters.narrowedTargets, 0u);
        EXPECT_LT(r->bToA.counters.narrowedTargets, a.size() - 1);  // A's points near B's core
    }
}

// Ties between the core's answer and a stray's: the stray and its nearest
// target are the core's witness pair moved by 2048 along x (coordinates on
// a 2^-12 grid in x, so the move is exact in float32 and the distances are
// the same double). The larger value, on a tie the smaller query index:
// the core's witness when the stray comes after it, the stray at index 0.
TEST(NarrowedTargets, TiesBetweenTheCoreAndAStrayTakeTheSmallerQueryIndex) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<glm::vec3> a = farCluster(1500, 1e-2f, 0, 91), b = farCluster(1400, 1e-2f, 0, 92);
    for (auto* set : {&a, &b})
        for (auto& p : *set) p.x = std::round(p.x * 4096.0f) / 4096.0f;
    const oracle::DirectedExact base = oracle::bruteForceDirected(a, b);
    const glm::vec3 move(2048.0f, 0.0f, 0.0f);
    const glm::vec3 stray = a[base.queryIndex] + move, twin = b[base.targetIndex] + move;
    ASSERT_EQ(stray - move, a[base.queryIndex]);  // exact moves
    ASSERT_EQ(twin - move, b[base.targetIndex]);
    b.push_back(twin);
    for (bool first : {false, true}) {
        SCOPED_TRACE(first ? "stray first" : "stray last");
        std::vector<glm::vec3> q = a;
        q.insert(first ? q.begin() : q.end(), stray);
        const oracle::DirectedExact want = oracle::bruteForceDirected(q, b);
        ASSERT_EQ(want.distance, base.distance);  // the tie is there
        EXPECT_EQ(want.queryIndex, first ? 0u : base.queryIndex);
        ASSERT_TRUE(narrowing(q, b) && narrowing(q, b)->joint);
        for (bool perPoint : {false, true}) {
            CallOptions call;
            call.perPointDistances = perPoint;
            Result<HausdorffResult> r = engine->compute(q, b, call);
            ASSERT_TRUE(r) << r.error().message;
            expectExact(*r, q, b, perPoint);
        }
    }
}

// Pairs of the device ingest (packed float32, no small-pair scan) look for
// narrowing from the host's boxes or from the device's, which it then
// leaves (Tuning::narrowHostBounds), and the narrowed calls take the device
// ingest or the host views (Tuning::narrowedIngest; lavapipe's default is
// the views, a GPU's the ingest): the same exact answers every way.
TEST(NarrowedTargets, DeviceIngestNarrowsFromEitherBoxes) {
    std::vector<glm::vec3> a = farCluster(3000, 1e-3f, 0, 101), b = farCluster(2800, 1e-3f, 0, 102);
    const glm::vec3 far(0.0f, 1700.0f, 0.0f);
    a.push_back(far);
    b.push_back(far);
    const std::vector<glm::vec3> one = farCluster(2600, 1e-3f, 5, 103), c = farCluster(2700, 1e-3f, 0, 104);
    for (int way = 0; way < 4; ++way) {
        const bool hostBounds = way % 2 == 1, narrowedIngest = way / 2 == 1;
        SCOPED_TRACE(std::string(hostBounds ? "host bounds" : "device bounds") +
                     (narrowedIngest ? ", narrowed calls ingested" : ", narrowed calls on host views"));
        EngineOptions options = test::engineUnderTest();
        options.tuning = Tuning{};
        options.tuning->smallPairWork = 0;
        options.tuning->narrowHostBounds = hostBounds;
        options.tuning->narrowedIngest = narrowedIngest;
        RTHDIST_REQUIRE_ENGINE(engine, options);
        for (auto [q, t] : {std::pair{a, b}, std::pair{one, c}, std::pair{c, one}}) {
            for (bool perPoint : {false, true}) {
                CallOptions call;
                call.perPointDistances = perPoint;
                Result<HausdorffResult> r = engine->compute(q, t, call);
                ASSERT_TRUE(r) << r.error().message;
                expectExact(*r, q, t, perPoint);
                EXPECT_GT(r->aToB.counters.narrowedTargets + r->bToA.counters.narrowedTargets, 0u);
            }
        }
    }
}

// A device-ingest pair past kNarrowCheckPoints narrows too (from the
// device's bounds; until session 17 it was ingested as it was and every
// cluster query went to the rays: 8 s for 5M + 5M on an H200). A 1 mm
// lattice of 128^3 points at spacing 2^-17 m and one common point 1.7 km
// away in each set, B the lattice moved by 2^-19 m along x (both in one
// shuffled order): every cluster query's nearest is its twin at exactly
// 2^-19 (all coordinates float values), so H = 2^-19 and both witnesses are
// query 0 and target 0 (the smallest indices of the tie).
TEST(NarrowedTargets, IngestPairsPastTheHostCheckSizeNarrowToo) {
    constexpr int kSide = 128;
    constexpr float kStep = 0x1p-17f, kShift = 0x1p-19f;
    std::vector<glm::vec3> a, b;
    a.reserve(size_t(kSide) * kSide * kSide + 1);
    b.reserve(a.capacity());
    for (int z = 0; z < kSide; ++z)
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x) {
                const glm::vec3 p(float(x) * kStep, float(y) * kStep, float(z) * kStep);
                a.push_back(p);
                b.push_back(p + glm::vec3(kShift, 0.0f, 0.0f));
            }
    // One shuffle for both (twins keep one index): in lattice order a
    // strided sample of the queries would see x = 0 only (its stride is a
    // multiple of 128) and no core would split off.
    std::vector<size_t> order(a.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), std::mt19937_64(17));
    std::vector<glm::vec3> sa(a.size()), sb(b.size());
    for (size_t i = 0; i < order.size(); ++i) {
        sa[i] = a[order[i]];
        sb[i] = b[order[i]];
    }
    a = std::move(sa);
    b = std::move(sb);
    const glm::vec3 far(1000.0f, 1000.0f, 1000.0f);
    a.push_back(far);
    b.push_back(far);
    ASSERT_GT(a.size() + b.size(), api::kNarrowCheckPoints);
    RTHDIST_REQUIRE_ENGINE(engine, test::engineUnderTest());
    Result<HausdorffResult> r = engine->compute(a, b);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->hausdorff, double(kShift));
    for (const Directed* d : {&r->aToB, &r->bToA}) {
        EXPECT_EQ(d->distance, double(kShift));
        EXPECT_EQ(d->queryIndex, 0u);
        EXPECT_EQ(d->targetIndex, 0u);
        EXPECT_TRUE(d->certificate.confirmed);
    }
    EXPECT_GT(r->aToB.counters.narrowedTargets + r->bToA.counters.narrowedTargets, 0u);
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
    EXPECT_EQ(n->targets.listed, want);
    EXPECT_TRUE(n->strays.listed.empty());
    ASSERT_EQ(n->targets.view.count, want.size());
    for (size_t k = 0; k < want.size(); ++k) EXPECT_EQ(n->targets.view.at(k), glm::dvec3(t[want[k]]));
    EXPECT_EQ(want.size(), 800u + 4u);  // the strays are dropped, the cluster kept
}

// The kept-target test reads float32 targets against float boxes first
// (outside the reach's box: dropped; inside a box within reach: kept), the
// rest in double: the kept set is the double test's, also for targets a
// float step either side of the reach (faces, edges and corners of it).
TEST(NarrowTargets, FloatBoxesKeepWhatTheDoubleTestKeeps) {
    const std::vector<glm::vec3> q = farCluster(500, 1e-3f, 0, 111);
    const core::Bounds qBox = core::boundsOf(q);
    const double radius = glm::length(qBox.hi - qBox.lo) * (1.0 + 0x1p-30);  // d(q0, T) = 0 below
    std::vector<glm::vec3> t = {q[0], glm::vec3(1700.0f, 0.0f, 0.0f)};
    std::mt19937_64 rng(112);
    std::uniform_int_distribution<int> side(-1, 1);
    std::normal_distribution<double> g(0.0, 1.0);
    while (t.size() < 20000) {
        // A point at distance `radius` from the box: beyond a face, an edge or a corner.
        const glm::ivec3 s(side(rng), side(rng), side(rng));
        if (s == glm::ivec3(0)) continue;
        glm::dvec3 dir(std::abs(g(rng)), std::abs(g(rng)), std::abs(g(rng)));
        glm::dvec3 p;
        for (int k = 0; k < 3; ++k) dir[k] = s[k] == 0 ? 0.0 : dir[k];
        dir = glm::normalize(dir) * radius;
        for (int k = 0; k < 3; ++k)
            p[k] = s[k] < 0   ? qBox.lo[k] - dir[k]
                   : s[k] > 0 ? qBox.hi[k] + dir[k]
                              : qBox.lo[k] + (qBox.hi[k] - qBox.lo[k]) * std::abs(g(rng)) / 4.0;
        const glm::vec3 f(p);
        t.push_back(f);
        for (int k = 0; k < 3; ++k)
            for (float to : {-1.0f, 1.0f}) {
                glm::vec3 n = f;
                n[k] = std::nextafter(n[k], to);
                t.push_back(n);
            }
    }
    const std::optional<api::NarrowedTargets> n =
        api::narrowTargets(q, qBox, true, t, core::boundsOf(t), true, 2);
    ASSERT_TRUE(n);
    EXPECT_EQ(n->radius, radius);
    std::vector<uint64_t> want;
    for (size_t i = 0; i < t.size(); ++i) {
        const glm::dvec3 p(t[i]);
        const glm::dvec3 d = glm::max(glm::max(qBox.lo - p, p - qBox.hi), glm::dvec3(0.0));
        if (glm::dot(d, d) <= radius * radius) want.push_back(i);
    }
    EXPECT_GT(want.size(), 1000u);
    EXPECT_LT(want.size(), t.size() - 1000);
    EXPECT_EQ(n->targets.listed, want);
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

// A lattice in raster order (a voxel grid's points): a sample at a stride
// that is a multiple of its rows saw x = 0 alone, its box had no extent on
// x and no core split off (every other point lay outside it). The sample's
// place in each stride varies now: the core is the lattice, the strays the
// three far points.
TEST(NarrowTargets, RasterOrderLatticeSplitsOffItsStrays) {
    constexpr int kSide = 64;
    std::vector<glm::vec3> q;
    for (int z = 0; z < kSide; ++z)
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x) q.push_back(glm::vec3(float(x), float(y), float(z)) * 0x1p-16f);
    for (const glm::vec3& far :
         {glm::vec3(3000.0f, 0.0f, 0.0f), glm::vec3(0.0f, -2000.0f, 10.0f), glm::vec3(1.0f, 1.0f, 9000.0f)})
        q.push_back(far);
    const core::Bounds box = core::boundsOf(q);
    const std::optional<api::CoreSplit> split =
        api::splitCore(q, core::SetSummary{box, true}, true, core::largestMagnitude(box), 2);
    ASSERT_TRUE(split);
    EXPECT_EQ(split->strays, (std::vector<uint64_t>{q.size() - 3, q.size() - 2, q.size() - 1}));
    EXPECT_EQ(split->core.box.lo, glm::dvec3(0.0));
    EXPECT_EQ(split->core.box.hi, glm::dvec3(double(kSide - 1) * 0x1p-16));
}

TEST(NarrowTargets, GainThreshold) {
    EXPECT_TRUE(api::narrowingPays(256.0, 1.0));
    EXPECT_FALSE(api::narrowingPays(255.0, 1.0));
    EXPECT_TRUE(api::narrowingPays(1000.0, 0.0));
    EXPECT_TRUE(api::narrowingPays(1000.0, 0x1p-126));
    EXPECT_FALSE(api::narrowingPays(1000.0, 1e-40));  // below float32's normals: not searchable
}

// A double cluster whose own frame would lie below 2^-126 (a point 1e-40
// from its twin) beside a stray 1000 away: the pair stays whole, and the
// values are the brute force's (it was refused: "every coordinate lies
// within 5e-41 of the search origin", the cores' frame checked alone).
TEST(NarrowedTargets, ACoreBelowFloatNormalsLeavesThePairWhole) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::dvec3> a{{1e-40, 0.0, 0.0}, {1000.0, 0.0, 0.0}}, b{{0.0, 0.0, 0.0}};
    for (bool perPoint : {false, true}) {
        CallOptions call;
        call.perPointDistances = perPoint;
        Result<HausdorffResult> r = engine->compute(PointView(a), PointView(b), call);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->hausdorff, 1000.0);
        EXPECT_EQ(r->aToB.distance, 1000.0);
        EXPECT_EQ(r->aToB.queryIndex, 1u);
        EXPECT_EQ(r->bToA.distance, 1e-40);
        EXPECT_EQ(r->bToA.targetIndex, 0u);
        EXPECT_TRUE(r->aToB.certificate.confirmed);
        EXPECT_TRUE(r->bToA.certificate.confirmed);
    }
}

}  // namespace
}  // namespace rthdist
