// Per-point entries are exact on every backend and route (README "Per-point
// distances"; cpu/exact_nearest.hpp): double inputs whose frame two
// millimetre clusters kilometres apart stretch, where the float
// search's nearest pairs lie up to 2e (~4 mm here) from the nearest; each
// entry must equal a brute force in double (the smallest index on a tie),
// the pass must have mended some (Counters::perPointMended), and the
// witness's entry is the proven one. One call, pieces under a forced
// budget, and nearest-only calls.
#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <tuple>
#include <vector>

#include "api/engine_test_support.hpp"
#include "common/brute_force.hpp"
#include "common/rng.hpp"
#include "core/certificate.hpp"

namespace rthdist {
namespace {

std::vector<oracle::NearestExact> bruteNearest(const std::vector<glm::dvec3>& q,
                                               const std::vector<glm::dvec3>& t) {
    std::vector<oracle::NearestExact> out;
    for (const glm::dvec3& p : q) out.push_back(oracle::bruteForceNearestInDouble(p, t));
    return out;
}

// Two clusters of n / 2 points, each in a 1 mm cube, at a georeferenced
// place and `far` metres away: the frame spans kilometres (no core of all
// but a few points to narrow to), its float error e ~ 2^-20 of it dwarfs
// the clusters' spacing.
std::vector<glm::dvec3> strayedCluster(size_t n, double far, uint64_t seed) {
    test::Rng rng(seed);
    const glm::dvec3 at(512345.125, 5412345.5, 100.0);
    std::vector<glm::dvec3> p;
    for (size_t i = 0; i < n; ++i)
        p.push_back(at + (i % 2 == 0 ? glm::dvec3(far, -far, 0.5 * far) : glm::dvec3(0.0)) +
                    glm::dvec3(rng.uniform(0, 1e-3), rng.uniform(0, 1e-3), rng.uniform(0, 1e-3)));
    return p;
}

void expectExactEntries(const HausdorffResult& r, const std::vector<glm::dvec3>& a,
                        const std::vector<glm::dvec3>& b, bool nearestOnly) {
    for (auto [got, d, q, t] :
         {std::tuple{&r.aNearest, &r.aToB, &a, &b}, std::tuple{&r.bNearest, &r.bToA, &b, &a}}) {
        const std::vector<oracle::NearestExact> want = bruteNearest(*q, *t);
        ASSERT_EQ(got->nearest.size(), want.size());
        ASSERT_EQ(got->distance.size(), nearestOnly ? 0 : want.size());
        for (size_t i = 0; i < want.size(); ++i) {
            ASSERT_EQ(got->nearest[i], want[i].targetIndex) << "point " << i;
            if (!nearestOnly) ASSERT_EQ(got->distance[i], want[i].distance) << "point " << i;
        }
        EXPECT_GT(d->counters.perPointMended, 0u) << "no float pair was off: the case tests nothing";
        EXPECT_EQ(got->nearest[d->queryIndex], d->targetIndex);
    }
}

TEST(ExactPerPoint, EntriesAreTheBruteForcesInAFrameStretchedByStrays) {
    const std::vector<glm::dvec3> a = strayedCluster(3000, 2500.0, 81), b = strayedCluster(2000, 3100.0, 82);
    for (const uint64_t budget : {uint64_t(0), uint64_t(1) << 20}) {  // one call; pieces
        EngineOptions o = test::engineUnderTest();
        o.memoryBudget = budget;
        RTHDIST_REQUIRE_ENGINE(engine, o);
        for (const bool nearestOnly : {false, true}) {
            SCOPED_TRACE(testing::Message() << "budget " << budget << (nearestOnly ? ", nearest only" : ""));
            CallOptions call;
            call.perPointDistances = true;
            call.perPointNearestOnly = nearestOnly;
            Result<HausdorffResult> r = engine->compute(PointView(a), PointView(b), call);
            ASSERT_TRUE(r) << r.error().message;
            expectExactEntries(*r, a, b, nearestOnly);
            EXPECT_EQ(r->validationMessages, 0u);
        }
    }
}

// Doubles that are float32 values are searched as they are (origin 0), so
// their float pairs are only within a relative ~2^-21 of the nearest: far
// from each other, near ties among the targets are mis-ordered. Their
// per-point entries are exact too (float64 input), on prepared sets of one
// frame (Route::kPrepared), of two frames indexed again (kReframe: a set
// near the origin), against a host array and in computeBatch.
std::vector<glm::dvec3> floatValued(size_t n, glm::dvec3 at, double side, uint64_t seed) {
    test::Rng rng(seed);
    std::vector<glm::dvec3> p;
    for (size_t i = 0; i < n; ++i)
        p.push_back(glm::dvec3(
            glm::vec3(at + glm::dvec3(rng.uniform(0, side), rng.uniform(0, side), rng.uniform(0, side)))));
    return p;
}

TEST(ExactPerPoint, FloatValuedDoublesArePreparedAndMadeExact) {
    const std::vector<glm::dvec3> a = floatValued(400, glm::dvec3(524300.0, 5412345.0, 100.0), 20.0, 91);
    const std::vector<glm::dvec3> b = floatValued(400, glm::dvec3(530300.0, 5417345.0, 140.0), 20.0, 92);
    const std::vector<glm::dvec3> nearOrigin = floatValued(300, glm::dvec3(0.25, 0.5, 0.125), 1.0, 93);
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    CallOptions call;
    call.perPointDistances = true;
    uint64_t mended = 0;
    const auto check = [&](const Result<HausdorffResult>& r, const std::vector<glm::dvec3>& q,
                           const std::vector<glm::dvec3>& t, const char* what) {
        SCOPED_TRACE(what);
        ASSERT_TRUE(r) << r.error().message;
        for (auto [got, d, qq, tt] :
             {std::tuple{&r->aNearest, &r->aToB, &q, &t}, std::tuple{&r->bNearest, &r->bToA, &t, &q}}) {
            const std::vector<oracle::NearestExact> want = bruteNearest(*qq, *tt);
            ASSERT_EQ(got->nearest.size(), want.size());
            for (size_t i = 0; i < want.size(); ++i) {
                ASSERT_EQ(got->nearest[i], want[i].targetIndex) << "point " << i;
                ASSERT_EQ(got->distance[i], want[i].distance) << "point " << i;
            }
            mended += d->counters.perPointMended;
        }
    };
    Result<PreparedSet> pa = engine->prepare(PointView(a)), pb = engine->prepare(PointView(b)),
                        po = engine->prepare(PointView(nearOrigin));
    ASSERT_TRUE(pa && pb && po);
    check(engine->compute(*pa, *pb, call), a, b, "prepared, one frame");
    check(engine->compute(*pa, *po, call), a, nearOrigin, "prepared, two frames");
    check(engine->compute(PointView(a), PointView(b), call), a, b, "host arrays");
    const PreparedSet sets[] = {*pa, *pb, *po};
    const PairRef pairs[] = {{0, 1}, {0, 2}};
    std::vector<Result<HausdorffResult>> batch = engine->computeBatch(sets, pairs, call);
    ASSERT_EQ(batch.size(), 2u);
    check(batch[0], a, b, "batch, one frame");
    check(batch[1], a, nearOrigin, "batch, two frames");
    EXPECT_GT(mended, 0u) << "no float pair was off: the case tests nothing";
}

}  // namespace
}  // namespace rthdist
