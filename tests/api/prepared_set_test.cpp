// Prepared sets and batches (Engine::prepare, compute on prepared sets,
// computeBatch) on the backend under test: exact against the brute force and
// the same computation as the one-shot call, reused across calls, in both
// roles, in one or two frames, and released after their Engine.
#include <gtest/gtest.h>

#include <array>

#include <glm/geometric.hpp>

#include "common/brute_force.hpp"
#include "common/geo_cases.hpp"
#include "common/oracle_cases.hpp"
#include "common/oracle_memo.hpp"
#include "engine_test_support.hpp"

namespace rthdist::test {
namespace {

Result<PreparedSet> prepare(Engine& engine, const std::vector<glm::vec3>& points) {
    return engine.prepare(points);
}

// Prepares every cloud, runs one computeBatch of `pairs` and checks each
// result against its pair's one-shot call and the brute force; a pair naming
// a set past the clouds must be an error of its own.
void expectBatchEqualsSingleCalls(Engine& engine, const std::vector<std::vector<glm::vec3>>& clouds,
                                  const std::vector<PairRef>& pairs, const CallOptions& call,
                                  const std::string& name) {
    std::vector<PreparedSet> sets;
    for (const auto& cloud : clouds) {
        auto s = prepare(engine, cloud);
        ASSERT_TRUE(s) << s.error().message;
        sets.push_back(*s);
    }
    const auto results = engine.computeBatch(sets, pairs, call);
    ASSERT_EQ(results.size(), pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
        SCOPED_TRACE("pair " + std::to_string(i));
        if (pairs[i].b >= sets.size()) {
            ASSERT_FALSE(results[i]);
            EXPECT_EQ(results[i].error().code, ErrorCode::kInvalidArgument);
            continue;
        }
        ASSERT_TRUE(results[i]) << results[i].error().message;
        const auto& a = clouds[pairs[i].a];
        const auto& b = clouds[pairs[i].b];
        auto once = engine.compute(a, b, call);
        ASSERT_TRUE(once) << once.error().message;
        expectSameResult(*results[i], *once, oracleTolerance(a, b, once->hausdorff));
        expectMatchesOracle(OracleCase{name, i, a, b}, *results[i]);
    }
}

// Every oracle case through prepared sets: exact, and identical to one-shot.
TEST(PreparedSet, OracleCasesMatchOneShot) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<OracleCase> cases = makeOracleCases();
    for (size_t i = 0; i < cases.size(); i += 3) {  // a third of them: the one-shot suites run all
        const OracleCase& c = cases[i];
        SCOPED_TRACE(c.name);
        auto a = prepare(*engine, c.a);
        auto b = prepare(*engine, c.b);
        ASSERT_TRUE(a && b) << (a ? b.error().message : a.error().message);
        auto r = engine->compute(*a, *b);
        ASSERT_TRUE(r) << r.error().message;
        expectMatchesOracle(c, *r);
        auto once = engine->compute(c.a, c.b, CallOptions{});
        ASSERT_TRUE(once) << once.error().message;
        expectSameResult(*r, *once, oracleTolerance(c.a, c.b, once->hausdorff));
    }
}

// One reference against many: 100 calls reuse the same prepared sets.
TEST(PreparedSet, HundredCallsReuseTheSameSets) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const std::vector<glm::vec3> reference = randomCloud(20000, 1);
    std::vector<std::vector<glm::vec3>> scans;
    std::vector<HausdorffResult> oneShot;
    for (uint64_t k = 0; k < 5; ++k) {
        scans.push_back(
            randomCloud(3000 + 1000 * k, 10 + k, glm::vec3(0.01f * float(k)), 1.0f + 0.1f * float(k)));
        auto once = engine->compute(reference, scans.back(), CallOptions{});
        ASSERT_TRUE(once) << once.error().message;
        oneShot.push_back(*once);
    }
    auto ref = prepare(*engine, reference);
    ASSERT_TRUE(ref) << ref.error().message;
    std::vector<PreparedSet> prepared;
    for (const auto& scan : scans) {
        auto p = prepare(*engine, scan);
        ASSERT_TRUE(p) << p.error().message;
        prepared.push_back(*p);
    }
    // The first round builds what is built on first use (coarse search
    // levels, the CPU target index); later calls add nothing.
    auto held = [&] {
        uint64_t bytes = ref->deviceBytes() + ref->hostBytes();
        for (const PreparedSet& p : prepared) bytes += p.deviceBytes() + p.hostBytes();
        return bytes;
    };
    uint64_t afterFirstRound = 0;
    for (int call = 0; call < 100; ++call) {
        const size_t k = size_t(call) % scans.size();
        auto r = engine->compute(*ref, prepared[k]);
        ASSERT_TRUE(r) << "call " << call << ": " << r.error().message;
        SCOPED_TRACE("call " + std::to_string(call));
        expectSameResult(*r, oneShot[k], oracleTolerance(reference, scans[k], oneShot[k].hausdorff));
        EXPECT_EQ(r->timings.upload, 0.0);  // nothing uploaded again
        if (call + 1 == int(scans.size())) afterFirstRound = held();
        if (call >= int(scans.size())) EXPECT_EQ(held(), afterFirstRound);
    }
}

// A prepared set is a query set and a target set: (P, Q) mirrors (Q, P),
// and (P, P) is zero.
TEST(PreparedSet, QueryAndTargetRoles) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    auto p = prepare(*engine, randomCloud(5000, 3));
    auto q = prepare(*engine, randomCloud(4000, 4, glm::vec3(0.3f, 0.0f, 0.0f)));
    ASSERT_TRUE(p && q);
    auto pq = engine->compute(*p, *q);
    auto qp = engine->compute(*q, *p);
    auto pp = engine->compute(*p, *p);
    ASSERT_TRUE(pq && qp && pp);
    EXPECT_EQ(pq->hausdorff, qp->hausdorff);
    EXPECT_EQ(pq->aToB.distance, qp->bToA.distance);
    EXPECT_EQ(pq->aToB.queryIndex, qp->bToA.queryIndex);
    EXPECT_EQ(pq->aToB.targetIndex, qp->bToA.targetIndex);
    EXPECT_EQ(pq->bToA.distance, qp->aToB.distance);
    EXPECT_EQ(pp->hausdorff, 0.0);
}

// Batches: per-pair results equal the single calls; a bad pair is an error
// of its own and does not stop the others.
TEST(PreparedSet, BatchEqualsSingleCalls) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<std::vector<glm::vec3>> clouds;
    for (uint64_t k = 0; k < 6; ++k)
        clouds.push_back(randomCloud(2000 + 500 * k, 40 + k, glm::vec3(0.05f * float(k))));
    CallOptions call;
    call.perPointDistances = true;
    expectBatchEqualsSingleCalls(*engine, clouds, {{0, 1}, {0, 2}, {3, 4}, {5, 0}, {2, 2}, {1, 9}, {4, 3}},
                                 call, "batch");
}

// Batches of small pairs (on GPU backends scanned whole, every pair in one
// submission: gpu_algo/small_pairs.hpp): every oracle case small enough for
// that on every device, in one computeBatch, exact against the brute force;
// directed and per-point batches too (each query's nearest distance and a
// nearest target at that distance).
TEST(PreparedSet, SmallPairBatchMatchesTheOracle) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<OracleCase> cases;
    for (OracleCase& c : makeOracleCases())
        if (c.a.size() * c.b.size() <= (size_t(1) << 20)) cases.push_back(std::move(c));
    ASSERT_GE(cases.size(), 100u);
    std::vector<PreparedSet> sets;
    std::vector<PairRef> pairs;
    for (const OracleCase& c : cases) {
        for (const auto* points : {&c.a, &c.b}) {
            auto s = prepare(*engine, *points);
            ASSERT_TRUE(s) << c.name << ": " << s.error().message;
            sets.push_back(*s);
        }
        pairs.push_back({sets.size() - 2, sets.size() - 1});
    }
    for (bool directed : {false, true}) {
        for (bool perPoint : {false, true}) {
            SCOPED_TRACE("directed " + std::to_string(directed) + " perPoint " + std::to_string(perPoint));
            CallOptions call;
            call.directedOnly = directed;
            call.perPointDistances = perPoint;
            const auto results = engine->computeBatch(sets, pairs, call);
            ASSERT_EQ(results.size(), pairs.size());
            for (size_t i = 0; i < cases.size(); ++i) {
                const OracleCase& c = cases[i];
                ASSERT_TRUE(results[i]) << c.name << ": " << results[i].error().message;
                const HausdorffResult& r = *results[i];
                expectMatchesOracle(c, r, directed);
                EXPECT_EQ(r.validationMessages, 0u);
                if (!perPoint) continue;
                const double tol = oracleTolerance(c.a, c.b, r.hausdorff);
                const std::vector<double> nn = oracle::memoNearest(c.a, c.b);
                ASSERT_EQ(r.aNearest.distance.size(), c.a.size()) << c.name;
                for (size_t q = 0; q < c.a.size(); ++q) {
                    ASSERT_NEAR(r.aNearest.distance[q], nn[q], tol) << c.name << " query " << q;
                    ASSERT_LT(r.aNearest.nearest[q], c.b.size());
                    ASSERT_EQ(r.aNearest.distance[q],
                              glm::length(glm::dvec3(c.a[q]) - glm::dvec3(c.b[r.aNearest.nearest[q]])));
                }
                EXPECT_EQ(r.bNearest.distance.size(), directed ? 0u : c.b.size()) << c.name;
            }
        }
    }
}

// One-shot calls of small pairs (on GPU backends scanned whole in one
// submission, from the host's float copies): every oracle case small enough
// on every device, exact against the brute force, for H, directed and
// per-point calls; georeferenced doubles through their own frame.
TEST(PreparedSet, SmallOneShotPairsMatchTheOracle) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    size_t tested = 0;
    for (const OracleCase& c : makeOracleCases()) {
        if (c.a.size() * c.b.size() > (size_t(1) << 20)) continue;
        ++tested;
        SCOPED_TRACE(c.name);
        for (bool directed : {false, true}) {
            CallOptions call;
            call.directedOnly = directed;
            call.perPointDistances = (c.seed % 2) == 0;
            auto r = engine->compute(c.a, c.b, call);
            ASSERT_TRUE(r) << r.error().message;
            expectMatchesOracle(c, *r, directed);
            EXPECT_EQ(r->validationMessages, 0u);
            if (!call.perPointDistances) continue;
            const std::vector<double> nn = oracle::memoNearest(c.a, c.b);
            ASSERT_EQ(r->aNearest.distance.size(), c.a.size());
            for (size_t q = 0; q < c.a.size(); ++q)
                ASSERT_NEAR(r->aNearest.distance[q], nn[q], oracleTolerance(c.a, c.b, r->hausdorff)) << q;
        }
    }
    EXPECT_GE(tested, 100u);
    for (const GeoCase& g : makeGeoCases()) {
        if (g.a.size() * g.b.size() > (size_t(1) << 20)) continue;
        SCOPED_TRACE(g.name);
        auto r = engine->compute(g.a, g.b, CallOptions{});
        ASSERT_TRUE(r) << r.error().message;
        expectMatchesGeoOracle(g, *r);
    }
}

// A batch mixing small pairs, a pair too large to be scanned whole, the same
// set on both sides and a bad reference: each result as its single call's.
TEST(PreparedSet, MixedBatchEqualsSingleCalls) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<std::vector<glm::vec3>> clouds{randomCloud(40000, 70),
                                               randomCloud(30000, 71, glm::vec3(0.02f))};
    for (uint64_t k = 0; k < 4; ++k)
        clouds.push_back(
            randomCloud(300 + 400 * k, 72 + k, glm::vec3(0.1f * float(k)), 1.0f + 0.5f * float(k)));
    expectBatchEqualsSingleCalls(*engine, clouds, {{2, 3}, {0, 1}, {4, 4}, {5, 2}, {3, 7}, {1, 5}, {4, 5}},
                                 CallOptions{}, "mixed");
}

// Georeferenced doubles: sets prepared in their own frames meet in the
// union's frame (indexed afresh); sets given one origin reuse their indexes;
// an origin that would break the bound is not used. All exact in double.
TEST(PreparedSet, DoubleSetsInOneOrTwoFrames) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    for (const GeoCase& c : makeGeoCases()) {
        SCOPED_TRACE(c.name);
        auto a = engine->prepare(c.a);
        ASSERT_TRUE(a) << a.error().message;
        PrepareOptions sameFrame;
        sameFrame.origin = a->origin();
        PrepareOptions farOrigin;
        farOrigin.origin = glm::dvec3(0.0);
        auto bOwn = engine->prepare(c.b);
        auto bShared = engine->prepare(c.b, sameFrame);
        auto aFar = engine->prepare(c.a, farOrigin);
        auto bFar = engine->prepare(c.b, farOrigin);
        ASSERT_TRUE(bOwn && bShared && aFar && bFar);
        EXPECT_EQ(bShared->origin(), a->origin());
        for (auto [x, y] : {std::pair{&*a, &*bOwn}, std::pair{&*a, &*bShared}, std::pair{&*aFar, &*bFar}}) {
            auto r = engine->compute(*x, *y);
            ASSERT_TRUE(r) << r.error().message;
            expectMatchesGeoOracle(c, *r);
        }
    }
}

TEST(PreparedSet, SetOfAnotherEngineIsAnError) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::string whyNot;
    auto other = makeEngine(engineUnderTest(), whyNot);
    ASSERT_TRUE(other) << whyNot;
    auto mine = prepare(*engine, randomCloud(100, 5));
    auto theirs = prepare(*other, randomCloud(100, 6));
    ASSERT_TRUE(mine && theirs);
    auto r = engine->compute(*mine, *theirs);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("another Engine"), std::string::npos);
}

TEST(PreparedSet, BadInputIsAnErrorValue) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    std::vector<glm::vec3> empty;
    auto e = engine->prepare(empty);
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().code, ErrorCode::kInvalidArgument);
    std::vector<glm::vec3> nan{{0, 0, 0}, {0, std::numeric_limits<float>::quiet_NaN(), 0}};
    auto n = engine->prepare(nan);
    ASSERT_FALSE(n);
    EXPECT_NE(n.error().message.find("point 1"), std::string::npos) << n.error().message;
    PrepareOptions bits;
    bits.bits = 99;
    auto b = engine->prepare(randomCloud(10, 1), bits);
    ASSERT_FALSE(b);
    EXPECT_EQ(b.error().code, ErrorCode::kInvalidArgument);
}

// What a set holds is reported, its bit count is the one asked for, and it
// may outlive the Engine that prepared it.
TEST(PreparedSet, MemoryBitsAndLifetime) {
    std::optional<PreparedSet> kept;
    {
        RTHDIST_REQUIRE_TEST_ENGINE(engine);
        PrepareOptions o;
        o.bits = 4;
        auto s = engine->prepare(randomCloud(50000, 7), o);
        ASSERT_TRUE(s) << s.error().message;
        EXPECT_EQ(s->size(), 50000u);
        EXPECT_EQ(s->bits(), 4);
        EXPECT_GE(s->hostBytes(), 50000u * 12);
        if (engine->backend() == Backend::kCpu) {
            EXPECT_EQ(s->deviceBytes(), 0u);
        } else {
            EXPECT_GE(s->deviceBytes(), 50000u * 16);  // the sorted points at least
        }
        kept = *s;
    }
    EXPECT_EQ(kept->size(), 50000u);
    kept.reset();  // destroys the index after its Engine: the device is kept alive until here
}

}  // namespace
}  // namespace rthdist::test
