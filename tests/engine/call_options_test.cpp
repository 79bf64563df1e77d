// Per-call options on one Engine (no new device between calls) and
// cancellation, on the backend under test.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "common/brute_force.hpp"
#include "common/oracle_cases.hpp"
#include "engine/engine_test_support.hpp"

namespace rthdist::test {
namespace {

// Direction, per-point output, radius growth and bit count change from call
// to call; every result is exact and per-point distances are every query's
// brute-force NN.
TEST(CallOptions, ChangeBetweenCallsOfOneEngine) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const OracleCase c{"call-options", 21, randomCloud(4000, 21),
                       randomCloud(3000, 22, glm::vec3(0.2f, 0.1f, 0.0f))};
    auto pa = engine->prepare(c.a);
    auto pb = engine->prepare(c.b);
    ASSERT_TRUE(pa && pb);
    const std::vector<double> nnA = oracle::bruteForceNearest(c.a, c.b);
    for (bool directed : {false, true}) {
        for (bool perPoint : {false, true}) {
            for (float growth : {1.5f, 2.0f, 4.0f}) {
                for (int bits : {0, 3, 6}) {
                    CallOptions call;
                    call.directedOnly = directed;
                    call.perPointDistances = perPoint;
                    call.radiusGrowth = growth;
                    call.bits = bits;
                    SCOPED_TRACE("directed " + std::to_string(directed) + " perPoint " +
                                 std::to_string(perPoint) + " growth " + std::to_string(growth) + " bits " +
                                 std::to_string(bits));
                    auto once = engine->compute(c.a, c.b, call);
                    auto prepared = engine->compute(*pa, *pb, call);
                    ASSERT_TRUE(once && prepared);
                    for (const HausdorffResult* r : {&*once, &*prepared}) {
                        expectMatchesOracle(c, *r, directed);
                        EXPECT_EQ(r->validationMessages, 0u);
                        if (!perPoint) continue;
                        ASSERT_EQ(r->aNearest.distance.size(), c.a.size());
                        for (size_t i = 0; i < c.a.size(); ++i)
                            ASSERT_NEAR(r->aNearest.distance[i], nnA[i], 1e-6) << "query " << i;
                        EXPECT_EQ(r->bNearest.distance.empty(), directed);
                    }
                    if (bits != 0) EXPECT_EQ(once->aToB.counters.bits, uint32_t(bits));
                }
            }
        }
    }
}

TEST(CallOptions, InvalidCallOptionsAreErrorValues) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const auto a = randomCloud(100, 1), b = randomCloud(100, 2);
    CallOptions growth;
    growth.radiusGrowth = 1.0f;
    CallOptions bits;
    bits.bits = -1;
    for (const CallOptions* call : {&growth, &bits}) {
        auto r = engine->compute(a, b, *call);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    }
    auto ok = engine->compute(a, b, CallOptions{});
    EXPECT_TRUE(ok) << ok.error().message;
}

// A flag set from the progress callback (at the first search report) stops
// the call with kCancelled; a flag set before the call stops it at once; the
// Engine and the prepared sets stay usable and exact afterwards.
TEST(CallOptions, CancellationStopsTheCallAndKeepsTheEngine) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const OracleCase c{"cancel", 31, randomCloud(20000, 31),
                       randomCloud(20000, 32, glm::vec3(0.5f, 0.0f, 0.0f))};
    auto pa = engine->prepare(c.a);
    auto pb = engine->prepare(c.b);
    ASSERT_TRUE(pa && pb);
    std::atomic<bool> cancel{false};
    CallOptions call;
    call.cancel = &cancel;
    int reportsAfterCancel = 0;
    call.progress = [&](const char* stage, double) {
        if (cancel.load()) ++reportsAfterCancel;
        if (std::string(stage) == "search" || std::string(stage) == "cull") cancel.store(true);
    };
    for (bool prepared : {false, true}) {
        cancel.store(false);
        reportsAfterCancel = 0;
        auto r = prepared ? engine->compute(*pa, *pb, call) : engine->compute(c.a, c.b, call);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kCancelled) << r.error().message;
        EXPECT_LE(reportsAfterCancel, 1);               // the call stops at its next check
        auto before = engine->compute(*pa, *pb, call);  // flag still set: stops at once
        ASSERT_FALSE(before);
        EXPECT_EQ(before.error().code, ErrorCode::kCancelled);
        auto batch = engine->computeBatch(std::vector<PreparedSet>{*pa, *pb},
                                          std::vector<PairRef>{{0, 1}, {1, 0}}, call);
        ASSERT_EQ(batch.size(), 2u);
        for (const auto& b : batch) EXPECT_EQ(b.error().code, ErrorCode::kCancelled);
        auto after = engine->compute(*pa, *pb);
        ASSERT_TRUE(after) << after.error().message;
        expectMatchesOracle(c, *after);
        EXPECT_EQ(after->validationMessages, 0u);
    }
}

// The pipeline cache file: written by the first Engine, read by the next;
// a damaged file is ignored (and replaced), "off" writes nothing.
TEST(PipelineCache, WrittenReadAndRepaired) {
    if (engineUnderTest().backend == Backend::kCpu) {
        RTHDIST_REQUIRE_TEST_ENGINE(engine);
        EXPECT_EQ(engine->pipelineCachePath(), "");
        return;
    }
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("rthdist-cache-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    EngineOptions o = engineUnderTest();
    o.pipelineCacheDir = dir.string();
    const auto a = randomCloud(500, 1), b = randomCloud(400, 2);
    auto exactWith = [&](const EngineOptions& opts, const std::string& wantStatus) {
        std::string whyNot;
        auto engine = makeEngine(opts, whyNot);
        ASSERT_TRUE(engine) << whyNot;
        EXPECT_EQ(engine->pipelineCacheStatus().rfind(wantStatus, 0), 0u) << engine->pipelineCacheStatus();
        auto r = engine->compute(a, b, CallOptions{});
        ASSERT_TRUE(r) << r.error().message;
        expectMatchesOracle(OracleCase{"cache", 1, a, b}, *r);
        if (opts.pipelineCacheDir != "off") EXPECT_TRUE(fs::exists(engine->pipelineCachePath()));
    };
    exactWith(o, "none");    // no file yet: compiles, then writes it
    exactWith(o, "loaded");  // a new Engine reads it
    const fs::path file = fs::directory_iterator(dir)->path();
    {
        std::ofstream damage(file, std::ios::binary | std::ios::trunc);
        damage << std::string(100, 'x');
    }
    exactWith(o, "ignored");  // damaged: compiles again and replaces it
    exactWith(o, "loaded");
    EngineOptions off = o;
    off.pipelineCacheDir = "off";
    fs::remove_all(dir);
    exactWith(off, "none");
    EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
}  // namespace rthdist::test
