// Named GPU tests: errors as values, degenerate shapes (design.md §6), the
// paper's candidate-set gap (design.md §3), pair-buffer overflow, engine reuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include "common/brute_force.hpp"
#include "common/case_sample.hpp"
#include "common/oracle_cases.hpp"
#include "common/oracle_memo.hpp"
#include "common/scoped_env.hpp"
#include "gpu_algo/gpu_context_support.hpp"
#include "gpu_algo/gpu_hausdorff.hpp"
#include "gpu_test_support.hpp"

namespace rthdist::test {
namespace {

std::vector<glm::vec3> uniformCloud(size_t n, uint64_t seed, glm::vec3 offset, float extent = 1.0f) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, extent);
    std::vector<glm::vec3> p(n);
    for (auto& v : p) v = glm::vec3(u(rng), u(rng), u(rng)) + offset;
    return p;
}

// gpuOptions() with its tuning changed by `tune`.
Options tunedOptions(const std::function<void(Tuning&)>& tune) {
    Options o = gpuOptions();
    tune(*o.tuning);
    return o;
}

// Two engines: the first of tunedOptions(with), the second of
// tunedOptions(base) alone. Either is empty (whyNot says why) when no device
// runs the backend.
std::pair<std::optional<Engine>, std::optional<Engine>> enginesWithAndWithout(
    const std::function<void(Tuning&)>& with, std::string& whyNot,
    const std::function<void(Tuning&)>& base = [](Tuning&) {}) {
    std::optional<Engine> tuned = makeEngine(tunedOptions([&](Tuning& t) {
                                                 base(t);
                                                 with(t);
                                             }),
                                             whyNot);
    std::optional<Engine> plain = makeEngine(tunedOptions(base), whyNot);
    return {std::move(tuned), std::move(plain)};
}

void expectExact(Engine& engine, const std::string& name, uint64_t seed, std::vector<glm::vec3> a,
                 std::vector<glm::vec3> b) {
    OracleCase c{name, seed, std::move(a), std::move(b)};
    SCOPED_TRACE(name);
    auto r = engine.compute(c.a, c.b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectMatchesOracle(c, *r);
    EXPECT_EQ(r->validationMessages, 0u);
}

// The pipelines are made on up to 16 host threads at once (pipelines.cpp):
// engines whose pipelines came from one thread, two, or every hardware
// thread give one result on a pair whose queries go to the rays (the
// search's pipeline and every kernel of the cull, the search and the
// refinement in use), witnesses included (the ray counts vary with the
// early break's timing, as between two calls of one engine).
TEST(GpuEngine, PipelinesMadeOnOneThreadOrSeveralGiveOneResult) {
    RTHDIST_REQUIRE_CONTEXT(ctx);
    const std::vector<glm::vec3> a = uniformCloud(3000, 11, glm::vec3(0.0f));
    const std::vector<glm::vec3> b = uniformCloud(2000, 12, glm::vec3(0.6f, 0.0f, 0.0f));
    std::optional<HausdorffResult> first;
    for (const int threads : {1, 2, 0}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        auto engine = gpu_algo::GpuHausdorff::create(*ctx, "", threads, *gpuOptions().tuning);
        ASSERT_TRUE(engine) << engine.error().message;
        auto r = (*engine)->computeIndexed(a, b, 1.0, CallOptions{});
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_GT(r->aToB.counters.rays + r->bToA.counters.rays, 0u);
        if (!first) {
            first = *r;
            continue;
        }
        EXPECT_EQ(r->hausdorff, first->hausdorff);
        EXPECT_EQ(r->aToB.queryIndex, first->aToB.queryIndex);
        EXPECT_EQ(r->aToB.targetIndex, first->aToB.targetIndex);
        EXPECT_EQ(r->bToA.queryIndex, first->bToA.queryIndex);
        EXPECT_EQ(r->bToA.targetIndex, first->bToA.targetIndex);
    }
}

TEST(GpuEngine, EmptySetIsAnErrorValue) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a{{0, 0, 0}}, empty;
    auto r = engine->compute(a, empty);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("empty"), std::string::npos);
}

TEST(GpuEngine, NanCoordinateIsAnErrorValueNamingThePoint) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a{{0, 0, 0}, {1, std::numeric_limits<float>::quiet_NaN(), 0}}, b{{1, 1, 1}};
    auto r = engine->compute(a, b);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("point 1"), std::string::npos) << r.error().message;
}

TEST(GpuEngine, OnePointEach) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a{{1, 2, 3}}, b{{4, 6, 3}};
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_DOUBLE_EQ(r->hausdorff, 5.0);
    EXPECT_EQ(r->aToB.queryIndex, 0u);
    EXPECT_EQ(r->bToA.targetIndex, 0u);
}

TEST(GpuEngine, IdenticalSetsGiveZero) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    auto a = uniformCloud(3000, 11, glm::vec3(0.0f));
    auto r = engine->compute(a, a);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->hausdorff, 0.0);
}

TEST(GpuEngine, PaperCornerTestCounterexample) {
    // design.md §3: cell edge 1, q = 0.5, t1 = 1.99 (near corner), t2 = -0.1;
    // the true NN is t2 at 0.6. Padding points fix the grid to unit cells.
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a{{0.5f, 0, 0}};
    std::vector<glm::vec3> b{{1.99f, 0, 0}, {-0.1f, 0, 0}, {-8.0f, 0, 0}, {8.0f, 0, 0}};
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_NEAR(r->aToB.distance, 0.6, 1e-6);
    EXPECT_EQ(r->aToB.targetIndex, 1u);
    expectExact(*engine, "corner-3d", 1, {{0.5f, 0.5f, 0.5f}},
                {{1.99f, 1.99f, 1.99f}, {-0.1f, 0.5f, 0.5f}, {-8, -8, -8}, {8, 8, 8}});
}

TEST(GpuEngine, PairBufferOverflowStaysExact) {
    // One bit per axis: 8 cells, every far query pairs with all of them, so
    // the pair buffer overflows and queries are redone at the same radius.
    Options o = gpuOptions();
    o.bits = 1;
    RTHDIST_REQUIRE_ENGINE(engine, o);
    expectExact(*engine, "overflow", 5, uniformCloud(40000, 5, glm::vec3(0.0f)),
                uniformCloud(30000, 6, glm::vec3(2.5f, 0.0f, 0.0f)));
}

TEST(GpuEngine, SlowRadiusGrowthGivesTheSameAnswer) {
    Options o = gpuOptions();
    o.radiusGrowth = 1.1f;
    RTHDIST_REQUIRE_ENGINE(engine, o);
    expectExact(*engine, "growth-1.1", 7, uniformCloud(5000, 7, glm::vec3(0.0f)),
                uniformCloud(4000, 8, glm::vec3(0.6f, 0.1f, 0.0f)));
}

TEST(GpuEngine, LargeOffsetsSmallExtent) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    expectExact(*engine, "offset-1e7", 9, uniformCloud(4000, 9, glm::vec3(1.0e7f, -1.0e7f, 5.4e6f), 50.0f),
                uniformCloud(3000, 10, glm::vec3(1.0e7f, -1.0e7f, 5.4e6f), 50.0f));
}

TEST(GpuEngine, ReusedEngineStaysExactAcrossSizes) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    const size_t sizes[][2] = {{20000, 10}, {10, 20000}, {1, 1}, {15000, 15000}, {700, 30}};
    uint64_t seed = 100;
    for (const auto& s : sizes) {
        expectExact(*engine, "reuse-" + std::to_string(s[0]) + "x" + std::to_string(s[1]), seed,
                    uniformCloud(s[0], seed, glm::vec3(0.0f)), uniformCloud(s[1], seed + 1, glm::vec3(0.3f)));
        seed += 2;
    }
}

// The radii of one search level run in one submission (the count of queries
// each searches kept on the device) or one per submission
// (Tuning::searchRadiiPerSubmission = 1): the same radii, so the same answers, witnesses
// and per-point distances (not the same counters: how many queries die early
// depends on when the running maximum rises, in either mode).
TEST(GpuEngine, RadiiInOneSubmissionEqualOnePerSubmission) {
    std::string whyNot;
    auto [single, fused] = enginesWithAndWithout([](Tuning& t) { t.searchRadiiPerSubmission = 1; }, whyNot);
    if (!single || !fused) GTEST_SKIP() << "no device for this backend: " << whyNot;
    uint32_t mostIterations = 0;
    for (uint64_t seed = 31; seed < 38; ++seed) {
        // The last: one bit per axis, far apart: the pair buffer overflows
        // (PairBufferOverflowStaysExact) and the search resumes at that radius.
        const bool overflow = seed == 37;
        const float apart = overflow ? 2.5f : 0.1f * float(seed - 30);
        OracleCase c{"radii-" + std::to_string(seed), seed,
                     uniformCloud(overflow ? 12000 : 3000 + 500 * seed, seed, glm::vec3(0.0f)),
                     uniformCloud(overflow ? 9000 : 5000, seed + 100, glm::vec3(apart, 0.05f, 0.0f))};
        SCOPED_TRACE(c.name);
        CallOptions call;
        call.perPointDistances = seed % 2 == 0;
        call.bits = overflow ? 1 : 0;
        auto one = single->compute(c.a, c.b, call);
        auto all = fused->compute(c.a, c.b, call);
        ASSERT_TRUE(one.ok()) << one.error().message;
        ASSERT_TRUE(all.ok()) << all.error().message;
        expectMatchesOracle(c, *all);
        EXPECT_EQ(all->hausdorff, one->hausdorff);
        EXPECT_EQ(all->aNearest.distance, one->aNearest.distance);
        EXPECT_EQ(all->bNearest.distance, one->bNearest.distance);
        EXPECT_EQ(all->aNearest.nearest, one->aNearest.nearest);
        EXPECT_EQ(all->bNearest.nearest, one->bNearest.nearest);
        for (const auto& [x, y] : {std::pair{&all->aToB, &one->aToB}, std::pair{&all->bToA, &one->bToA}}) {
            EXPECT_EQ(x->distance, y->distance);
            EXPECT_EQ(x->queryIndex, y->queryIndex);
            EXPECT_EQ(x->targetIndex, y->targetIndex);
            mostIterations = std::max(mostIterations, x->counters.iterations);
        }
        EXPECT_EQ(all->validationMessages, 0u);
    }
    EXPECT_GE(mostIterations, 2u);  // radii shared a submission
}

// A dense cloud with a few isolated points far from the other set (a noisy
// mask's outliers): their search is the tail whose radius grows by the
// square of the growth (RadiusSchedule::tailStep). Per-point distances and
// witnesses equal those with the plain growth (Tuning::squaredTailGrowth
// false) and
// the brute force; the tail takes fewer radius iterations.
TEST(GpuEngine, FarTailGrowsFasterAndStaysExact) {
    std::string whyNot;
    auto [plain, tail] = enginesWithAndWithout([](Tuning& t) { t.squaredTailGrowth = false; }, whyNot,
                                               [](Tuning& t) {
                                                   t.tailScanWork = 0;  // the tail traced, not scanned
                                                   t.tailScanStartWork = 0;
                                               });
    if (!plain || !tail) GTEST_SKIP() << "no device for this backend: " << whyNot;
    std::vector<glm::vec3> a = uniformCloud(6000, 41, glm::vec3(0.0f));
    const std::vector<glm::vec3> far = uniformCloud(60, 42, glm::vec3(-40.0f), 80.0f);
    a.insert(a.end(), far.begin(), far.end());
    const std::vector<glm::vec3> b = uniformCloud(5000, 43, glm::vec3(0.3f, 0.0f, 0.0f));
    CallOptions call;
    call.perPointDistances = true;
    auto p = plain->compute(a, b, call);
    auto t = tail->compute(a, b, call);
    ASSERT_TRUE(p.ok()) << p.error().message;
    ASSERT_TRUE(t.ok()) << t.error().message;
    const std::vector<double> want = oracle::bruteForceNearest(a, b);
    EXPECT_EQ(t->aNearest.distance, want);
    EXPECT_EQ(t->aNearest.distance, p->aNearest.distance);
    EXPECT_EQ(t->aNearest.nearest, p->aNearest.nearest);
    EXPECT_EQ(t->bNearest.distance, p->bNearest.distance);
    EXPECT_EQ(t->hausdorff, p->hausdorff);
    EXPECT_EQ(t->aToB.queryIndex, p->aToB.queryIndex);
    EXPECT_LT(t->aToB.counters.iterations, p->aToB.counters.iterations);
    EXPECT_EQ(t->validationMessages, 0u);
}

// The search's far tail scans every cell of a coarse level instead of
// tracing more radii (RadiusSchedule::tailLevel): the same distances as
// the brute force and the same results as the radii alone, for far outliers
// per point and for H alone (where the running maximum kills queries), with
// every target doubled (copies), and with one bit per axis (the pair buffer
// overflows before the tail); and with the scan taking the queries the
// neighbourhood pass left before any radius (Tuning::tailScanStartWork, off
// by default).
TEST(GpuEngine, TailScanEqualsRadiiAndBruteForce) {
    std::string whyNot;
    std::optional<Engine> radiiOnly, tail, fromStart;
    radiiOnly = makeEngine(tunedOptions([](Tuning& t) {
                               t.tailScanWork = 0;
                               t.tailScanStartWork = 0;
                           }),
                           whyNot);
    tail = makeEngine(gpuOptions(), whyNot);
    fromStart = makeEngine(tunedOptions([](Tuning& t) { t.tailScanStartWork = uint64_t(1) << 32; }), whyNot);
    if (!radiiOnly || !tail || !fromStart) GTEST_SKIP() << "no device for this backend: " << whyNot;
    uint64_t scanned = 0;
    uint32_t scannedWhole = 0;  // directions whose whole search was one scan
    for (uint64_t seed = 61; seed < 66; ++seed) {
        const bool overflow = seed == 65;  // as in RadiiInOneSubmissionEqualOnePerSubmission
        OracleCase c{
            "tail-" + std::to_string(seed), seed,
            uniformCloud(overflow ? 12000 : 4000, seed, glm::vec3(0.0f)),
            uniformCloud(overflow ? 9000 : 3000, seed + 20, glm::vec3(overflow ? 2.5f : 0.2f, 0.05f, 0.0f))};
        SCOPED_TRACE(c.name);
        const std::vector<glm::vec3> far = uniformCloud(80, seed + 10, glm::vec3(-30.0f), 60.0f);
        c.a.insert(c.a.end(), far.begin(), far.end());
        if (seed == 63) {
            const std::vector<glm::vec3> copies = c.b;
            c.b.insert(c.b.end(), copies.begin(), copies.end());
        }
        CallOptions call;
        call.perPointDistances = seed % 2 == 0;
        call.bits = overflow ? 1 : 0;
        auto r = radiiOnly->compute(c.a, c.b, call);
        ASSERT_TRUE(r.ok()) << r.error().message;
        EXPECT_EQ(r->aToB.counters.tailScanned + r->bToA.counters.tailScanned, 0u);
        for (Engine* e : {&*tail, &*fromStart}) {
            auto t = e->compute(c.a, c.b, call);
            ASSERT_TRUE(t.ok()) << t.error().message;
            scanned += t->aToB.counters.tailScanned + t->bToA.counters.tailScanned;
            for (const Directed* d : {&t->aToB, &t->bToA})
                scannedWhole += d->counters.iterations == 1 && d->counters.tailScanned > 0 &&
                                d->counters.tailScanned == d->counters.survivingQueries;
            expectMatchesOracle(c, *t);
            EXPECT_EQ(t->hausdorff, r->hausdorff);
            EXPECT_EQ(t->aToB.distance, r->aToB.distance);
            EXPECT_EQ(t->bToA.distance, r->bToA.distance);
            if (call.perPointDistances) {
                EXPECT_EQ(t->aNearest.distance, oracle::memoNearest(c.a, c.b));
                EXPECT_EQ(t->bNearest.distance, oracle::memoNearest(c.b, c.a));
                EXPECT_EQ(t->aNearest.nearest, r->aNearest.nearest);
                EXPECT_EQ(t->bNearest.nearest, r->bNearest.nearest);
            }
            EXPECT_EQ(t->validationMessages, 0u);
        }
    }
    EXPECT_GT(scanned, 0u);
    EXPECT_GT(scannedWhole, 0u);
}

// A dense cluster with one stray point far from it in each set (a LiDAR
// scan with one stray return): the stray's search is the sweep.
OracleCase farClusterCase(uint64_t seed, size_t n, double gap) {
    OracleCase c{"far-cluster-" + std::to_string(seed), seed, uniformCloud(n, seed, glm::vec3(0.0f), 2e-3f),
                 uniformCloud(n, seed + 1, glm::vec3(0.0f), 2e-3f)};
    c.a.push_back(glm::vec3(float(gap), 0.25f, -0.5f));
    c.b.push_back(glm::vec3(-0.5f, float(-gap * 0.8), 1.0f));
    return c;
}

// The sweep (CandidateSearch::sweepWork: every open query against every
// target, no rays) gives the brute force's distances and the radii's
// results: for a far cluster with strays (the default limit takes it, in a
// few submissions), for far outliers per point and for H alone, with every
// target doubled (ties: the smallest index), and with the sweep taking every
// query the neighbourhood pass left.
TEST(GpuEngine, SweepEqualsRadiiAndBruteForce) {
    std::string whyNot;
    // (Strays of their own would send the far clusters to their cores, where
    // nothing is swept: the whole search is what these engines test.)
    std::optional<Engine> radiiOnly = makeEngine(tunedOptions([](Tuning& t) {
                                                     t.tailScanWork = 0;
                                                     t.tailScanStartWork = 0;
                                                     t.coresForOwnStrays = false;
                                                 }),
                                                 whyNot);
    std::optional<Engine> always = makeEngine(tunedOptions([](Tuning& t) {
                                                  t.sweepWork = uint64_t(1) << 40;
                                                  t.coresForOwnStrays = false;
                                              }),
                                              whyNot);
    std::optional<Engine> byDefault = makeEngine(tunedOptions([](Tuning& t) {
                                                     t.sweepWork.reset();
                                                     t.coresForOwnStrays = false;
                                                 }),
                                                 whyNot);
    if (!radiiOnly || !always || !byDefault) GTEST_SKIP() << "no device for this backend: " << whyNot;
    std::vector<OracleCase> cases{farClusterCase(71, 3000, 3000.0), farClusterCase(72, 2000, 40.0)};
    for (uint64_t seed = 73; seed < 76; ++seed) {
        OracleCase c{"outliers-" + std::to_string(seed), seed, uniformCloud(3000, seed, glm::vec3(0.0f)),
                     uniformCloud(2500, seed + 20, glm::vec3(0.2f, 0.05f, 0.0f))};
        const std::vector<glm::vec3> far = uniformCloud(40, seed + 10, glm::vec3(-30.0f), 60.0f);
        c.a.insert(c.a.end(), far.begin(), far.end());
        if (seed == 74) {
            const std::vector<glm::vec3> copies = c.b;
            c.b.insert(c.b.end(), copies.begin(), copies.end());
        }
        cases.push_back(std::move(c));
    }
    uint64_t sweptByDefault = 0;
    // Sanitizer runs take every caseStride()-th case; the far clusters first, so one always runs.
    for (const OracleCase& c : sampledCases(cases)) {
        SCOPED_TRACE(c.name);
        for (bool perPoint : {false, true}) {
            CallOptions call;
            call.perPointDistances = perPoint;
            auto r = radiiOnly->compute(c.a, c.b, call);
            ASSERT_TRUE(r.ok()) << r.error().message;
            EXPECT_EQ(r->aToB.counters.tailScanned + r->bToA.counters.tailScanned, 0u);
            for (Engine* e : {&*always, &*byDefault}) {
                auto t = e->compute(c.a, c.b, call);
                ASSERT_TRUE(t.ok()) << t.error().message;
                for (const Directed* d : {&t->aToB, &t->bToA}) {
                    // The search's own answer was proven (no CPU recomputation).
                    EXPECT_TRUE(d->certificate.confirmed);
                    EXPECT_FALSE(d->certificate.recomputed) << d->certificate.failure;
                    if (e == &*always) EXPECT_EQ(d->counters.tailScanned, d->counters.survivingQueries);
                    if (e == &*byDefault && c.name.starts_with("far-cluster"))
                        sweptByDefault += d->counters.tailScanned;
                }
                expectMatchesOracle(c, *t);
                EXPECT_EQ(t->hausdorff, r->hausdorff);
                EXPECT_EQ(t->aToB.distance, r->aToB.distance);
                EXPECT_EQ(t->aToB.queryIndex, r->aToB.queryIndex);
                EXPECT_EQ(t->aToB.targetIndex, r->aToB.targetIndex);
                EXPECT_EQ(t->bToA.distance, r->bToA.distance);
                EXPECT_EQ(t->bToA.targetIndex, r->bToA.targetIndex);
                if (perPoint) {
                    EXPECT_EQ(t->aNearest.distance, oracle::memoNearest(c.a, c.b));
                    EXPECT_EQ(t->bNearest.distance, oracle::memoNearest(c.b, c.a));
                    EXPECT_EQ(t->aNearest.nearest, r->aNearest.nearest);
                    EXPECT_EQ(t->bNearest.nearest, r->bNearest.nearest);
                }
                EXPECT_EQ(t->validationMessages, 0u);
            }
        }
    }
    EXPECT_GT(sweptByDefault, 0u);
}

// Exact copies of a target are one position: a cell of copies is scanned
// through its first point alone, which the index build makes the copy of
// the smallest original index (the tie rule), whatever order the counting
// sort left (it is not stable). Targets are `distinct` points followed by
// their copies, so every per-point nearest index must lie in the first
// block: few copies a point (the cell's serial box), and more than
// RTHDIST_SERIAL_BOX copies (the parallel box reduction's fix pass).
TEST(GpuEngine, CopiesGoToTheSmallestIndex) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    CallOptions call;
    call.perPointDistances = true;
    for (const auto& [distinct, copies, bits] :
         {std::tuple<size_t, size_t, int>{1500, 3, 0}, std::tuple<size_t, size_t, int>{3000, 2, 1},
          std::tuple<size_t, size_t, int>{40, 100, 0}}) {
        call.bits = bits;  // 1: crowded cells, cut into leaves (copies end up in leaves of their own)
        for (uint64_t seed = 81; seed < 84; ++seed) {
            SCOPED_TRACE(std::to_string(distinct) + " x " + std::to_string(copies) + " bits " +
                         std::to_string(bits) + " seed " + std::to_string(seed));
            const std::vector<glm::vec3> a = uniformCloud(2000, seed, glm::vec3(0.0f));
            const std::vector<glm::vec3> base = uniformCloud(distinct, seed + 7, glm::vec3(0.1f, 0.0f, 0.0f));
            std::vector<glm::vec3> b;
            for (size_t k = 0; k < copies; ++k) b.insert(b.end(), base.begin(), base.end());
            auto r = engine->compute(a, b, call);
            ASSERT_TRUE(r.ok()) << r.error().message;
            EXPECT_EQ(r->aNearest.distance, oracle::bruteForceNearest(a, b));
            size_t past = 0;
            for (uint32_t t : r->aNearest.nearest) past += t >= distinct;
            EXPECT_EQ(past, 0u) << "per-point nearest indices name a later copy";
            EXPECT_LT(r->aToB.targetIndex, distinct);
        }
    }
}

// Per-point arrays handed back (Engine::recycle), of other sizes and
// holding stale values, are filled whole by the next call: the same
// distances and nearest points as fresh arrays and the brute force, for a
// pair the neighbourhood pass settles whole (its check behind the cull
// copies the nearest points) and for pairs that search.
TEST(GpuEngine, RecycledPerPointArraysAreFilledWhole) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    CallOptions call;
    call.perPointDistances = true;
    const std::vector<glm::vec3> same = uniformCloud(2500, 51, glm::vec3(0.0f));
    const std::vector<std::pair<std::vector<glm::vec3>, std::vector<glm::vec3>>> pairs = {
        {same, same},
        {uniformCloud(3000, 52, glm::vec3(0.0f)), uniformCloud(4000, 53, glm::vec3(0.6f, 0.0f, 0.0f))},
        {uniformCloud(5000, 54, glm::vec3(0.0f)), uniformCloud(2000, 55, glm::vec3(0.0f, 2.0f, 0.0f))},
    };
    uint32_t searched = 0, settledByCull = 0;
    for (size_t k = 0; k < pairs.size(); ++k) {
        SCOPED_TRACE(k);
        const auto& [a, b] = pairs[k];
        auto fresh = engine->compute(a, b, call);
        ASSERT_TRUE(fresh.ok()) << fresh.error().message;
        // Stale arrays: a's larger and out of range, b's smaller.
        HausdorffResult spent;
        spent.aNearest.distance.assign(a.size() + 77, -1.0);
        spent.aNearest.nearest.assign(a.size() + 77, UINT32_MAX);
        spent.bNearest.distance.assign(b.size() / 3, -1.0);
        spent.bNearest.nearest.assign(b.size() / 3, UINT32_MAX);
        engine->recycle(std::move(spent));
        auto again = engine->compute(a, b, call);
        ASSERT_TRUE(again.ok()) << again.error().message;
        EXPECT_EQ(again->aNearest.distance, oracle::bruteForceNearest(a, b));
        EXPECT_EQ(again->bNearest.distance, oracle::bruteForceNearest(b, a));
        EXPECT_EQ(again->aNearest.distance, fresh->aNearest.distance);
        EXPECT_EQ(again->aNearest.nearest, fresh->aNearest.nearest);
        EXPECT_EQ(again->bNearest.distance, fresh->bNearest.distance);
        EXPECT_EQ(again->bNearest.nearest, fresh->bNearest.nearest);
        for (size_t i = 0; i < a.size(); ++i)
            ASSERT_EQ(again->aNearest.distance[i],
                      glm::length(glm::dvec3(a[i]) - glm::dvec3(b[again->aNearest.nearest[i]])))
                << i;
        // The result's arrays go back again: the next pair reuses them.
        for (const Directed* d : {&again->aToB, &again->bToA})
            (d->counters.survivingQueries > 0 ? searched : settledByCull) += 1;
        engine->recycle(std::move(*again));
        EXPECT_EQ(fresh->validationMessages, 0u);
    }
    EXPECT_GE(searched, 1u);
    EXPECT_GE(settledByCull, 1u);
}

TEST(GpuEngine, CountersDescribeTheWork) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    auto a = uniformCloud(8000, 21, glm::vec3(0.0f));
    auto b = uniformCloud(6000, 22, glm::vec3(1.5f, 0.0f, 0.0f));
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const Counters& c = r->aToB.counters;
    EXPECT_EQ(c.queries, a.size());
    EXPECT_EQ(c.culledByNeighbourhood + c.survivingQueries, c.queries);
    EXPECT_GT(c.survivingQueries, 0u);  // the sets are apart: no query dies before a ray
    EXPECT_GE(c.rays, c.survivingQueries);
    EXPECT_GE(c.iterations, 1u);
    EXPECT_GT(c.occupiedCells, 0u);
    EXPECT_LE(c.occupiedCells, b.size());
    EXPECT_GT(r->timings.total, 0.0);
}

}  // namespace
}  // namespace rthdist::test

namespace rthdist::test {
namespace {

TEST(GpuEngine, HugeAndTinyMagnitudesAreScaledExactly) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a{{1e30f, 0, 0}}, b{{-1e30f, 0, 0}, {0, 1e30f, 0}};
    auto r = engine->compute(a, b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_NEAR(r->aToB.distance, std::sqrt(2.0) * 1e30, 1e24);
    EXPECT_EQ(r->aToB.targetIndex, 1u);
    expectExact(*engine, "huge", 31, uniformCloud(2000, 31, glm::vec3(3e25f), 1e25f),
                uniformCloud(1500, 32, glm::vec3(3.5e25f), 1e25f));
    expectExact(*engine, "tiny", 33, uniformCloud(2000, 33, glm::vec3(0.0f), 1e-30f),
                uniformCloud(1500, 34, glm::vec3(2e-31f), 1e-30f));
}

}  // namespace
}  // namespace rthdist::test
