// Issue 32 on the backend named by RTHDIST_TEST_BACKEND: every result carries
// a confirmed certificate whose witness is the result's; a deliberately broken
// search (core/search_mutant.hpp: candidates dropped) is caught by it and the
// direction recomputed, exact; and values that the float search cannot tell
// apart are settled in double.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

#include "common/oracle_cases.hpp"
#include "common/scoped_mutant.hpp"
#include "engine_test_support.hpp"

namespace rthdist::test {
namespace {

// A sample of the oracle cases: every seventh, at most 30k points a pair.
std::vector<OracleCase> sampledCases() {
    std::vector<OracleCase> out;
    const std::vector<OracleCase> all = makeOracleCases();
    for (size_t i = 0; i < all.size(); i += 7)
        if (all[i].a.size() + all[i].b.size() <= 30000) out.push_back(all[i]);
    return out;
}

void expectCertificateIsTheWitness(const Directed& d) {
    EXPECT_TRUE(d.certificate.confirmed);
    EXPECT_EQ(d.certificate.query, d.queryIndex);
    EXPECT_EQ(d.certificate.nearest, d.targetIndex);
    EXPECT_EQ(d.certificate.distance, d.distance);
}

// Each sampled case against the oracle, its directions' certificates the
// witness's; `visit` sees each direction.
template <class Visit>
void checkSampledCases(Engine& engine, Visit&& visit) {
    for (const OracleCase& c : sampledCases()) {
        SCOPED_TRACE(c.name);
        auto r = engine.compute(c.a, c.b);
        ASSERT_TRUE(r) << r.error().message;
        expectMatchesOracle(c, *r);
        for (const Directed* d : {&r->aToB, &r->bToA}) {
            expectCertificateIsTheWitness(*d);
            visit(*d);
        }
    }
}

TEST(Certificate, EveryResultCarriesAConfirmedProof) {
    auto engine = Engine::create(engineUnderTest());
    ASSERT_TRUE(engine) << engine.error().message;
    uint64_t banded = 0;
    checkSampledCases(*engine, [&](const Directed& d) {
        EXPECT_FALSE(d.certificate.recomputed);
        if (d.certificate.band > 0) ++banded;
    });
    EXPECT_GT(banded, 0u) << "no result came with a band";
}

// The mutant drops candidates: some directions come out wrong, the
// certificate fails for them and the Engine recomputes them on the CPU
// backend; every value is exact all the same. The mutant misses in the
// rays' refinement only, so the small-pair scan (an H200 scans every
// sampled case whole: no index, no rays), the sweep and the tail scan, which
// a GPU's schedule prefers for the sampled cases' few open queries, are off:
// open queries go to the rays on any device.
TEST(Certificate, MutantSearchIsCaughtAndRecomputed) {
    EngineOptions options = engineUnderTest();
    Tuning raysOnly;
    raysOnly.smallPairWork = 0;
    raysOnly.sweepWork = 0;
    raysOnly.tailScanWork = 0;
    raysOnly.tailScanStartWork = 0;
    options.tuning = raysOnly;
    auto engine = Engine::create(options);
    ASSERT_TRUE(engine) << engine.error().message;
    uint64_t recomputed = 0, directions = 0;
    {
        const test::ScopedSearchMutant mutant;
        checkSampledCases(*engine, [&](const Directed& d) {
            recomputed += d.certificate.recomputed ? 1 : 0;
            ++directions;
        });
    }
    std::printf("  the mutant's answers recomputed: %llu of %llu directions\n",
                static_cast<unsigned long long>(recomputed), static_cast<unsigned long long>(directions));
    EXPECT_GT(recomputed, 0u) << "the mutant never gave a wrong answer: the test tests nothing";
    // Without the mutant nothing is recomputed.
    auto r = engine->compute(sampledCases().back().a, sampledCases().back().b);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_FALSE(r->aToB.certificate.recomputed);
    EXPECT_FALSE(r->bToA.certificate.recomputed);
}

// Issue 32's second hole: float32 points at 1e-30 and 1e30 in one set. The
// float search sees (1e30, 0, 0) and (1e30, 1, 0) as one point; in double
// they are 1 apart, and so is h.
TEST(Certificate, FloatTiesAreSettledInDouble) {
    auto engine = Engine::create(engineUnderTest());
    ASSERT_TRUE(engine) << engine.error().message;
    const std::vector<glm::vec3> a = {{0.0f, 0.0f, 0.0f}, {1e-30f, 0.0f, 0.0f}, {1e30f, 0.0f, 0.0f}};
    const std::vector<glm::vec3> b = {{0.0f, 0.0f, 0.0f}, {1e30f, 1.0f, 0.0f}};
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->aToB.distance, 1.0);
    EXPECT_EQ(r->aToB.queryIndex, 2u);
    EXPECT_EQ(r->aToB.targetIndex, 1u);
    EXPECT_EQ(r->bToA.distance, 1.0);
    EXPECT_EQ(r->hausdorff, 1.0);
    expectCertificateIsTheWitness(r->aToB);
    expectCertificateIsTheWitness(r->bToA);
}

// A far query sees a dense cluster whose extent (2 mm) lies below the float
// slack at its distance (5 km): every cluster point is a candidate of its
// nearest. More than the device's candidate buffer holds: the host settles
// them in double, without a recomputation.
TEST(Certificate, AClusterSeenFromFarIsSettledInDouble) {
    auto engine = Engine::create(engineUnderTest());
    ASSERT_TRUE(engine) << engine.error().message;
    std::vector<glm::vec3> a = randomCloud(70000, 71, glm::vec3(0.0f), 2e-3f);
    const std::vector<glm::vec3> b = randomCloud(70000, 72, glm::vec3(0.0f), 2e-3f);
    a.emplace_back(3000.0f, 4000.0f, 0.0f);
    CallOptions call;
    call.directedOnly = true;
    auto r = engine->compute(a, b, call);
    ASSERT_TRUE(r) << r.error().message;
    double want = INFINITY;
    uint64_t nearest = 0;
    for (size_t t = 0; t < b.size(); ++t) {
        const glm::dvec3 d = glm::dvec3(a.back()) - glm::dvec3(b[t]);
        const double dist = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        if (dist < want) want = dist, nearest = t;
    }
    EXPECT_EQ(r->aToB.distance, want);
    EXPECT_EQ(r->aToB.queryIndex, a.size() - 1);
    EXPECT_EQ(r->aToB.targetIndex, nearest);
    expectCertificateIsTheWitness(r->aToB);
    EXPECT_FALSE(r->aToB.certificate.recomputed) << r->aToB.certificate.failure;
}

}  // namespace
}  // namespace rthdist::test
