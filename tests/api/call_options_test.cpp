// Per-call options on one Engine (no new device between calls) and
// cancellation, on the backend under test.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <span>
#include <string>
#include <thread>

#include <sys/stat.h>
#include <unistd.h>

#include "api/out_of_core.hpp"
#include "common/brute_force.hpp"
#include "common/case_sample.hpp"
#include "common/oracle_cases.hpp"
#include "engine_test_support.hpp"

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
    // All 36 combinations; sanitizer runs (caseStride() > 1) take 12: for each
    // (directed, perPoint) the three (growth g, bits k) with (g + k) % 3 fixed, so
    // each growth and each bit count still meets each direction and output
    // mode, and the options still change from call to call.
    const bool sampled = caseStride() > 1;
    for (bool directed : {false, true}) {
        for (bool perPoint : {false, true}) {
            for (size_t g = 0; g < 3; ++g) {
                for (size_t k = 0; k < 3; ++k) {
                    if (sampled && (g + k) % 3 != (2 * size_t(directed) + size_t(perPoint)) % 3) continue;
                    const float growth = std::array{1.5f, 2.0f, 4.0f}[g];
                    const int bits = std::array{0, 3, 6}[k];
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

// Per-point nearest only (CallOptions::perPointNearestOnly): the same
// nearest points, H and witnesses as the call with distances and
// PerPoint::distance empty — one-shot, after a recycled result whose arrays
// held distances, prepared, and on double input far from the origin (the
// witnesses restored in double).
TEST(CallOptions, PerPointNearestOnlyKeepsTheNearestPoints) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    const OracleCase c{"nearest-only", 23, randomCloud(4000, 23),
                       randomCloud(3000, 24, glm::vec3(0.3f, 0.1f, 0.0f))};
    CallOptions full;
    full.perPointDistances = true;
    CallOptions only = full;
    only.perPointNearestOnly = true;
    auto expectSame = [](const HausdorffResult& o, const HausdorffResult& f) {
        EXPECT_TRUE(o.aNearest.distance.empty());
        EXPECT_TRUE(o.bNearest.distance.empty());
        EXPECT_EQ(o.aNearest.nearest, f.aNearest.nearest);
        EXPECT_EQ(o.bNearest.nearest, f.bNearest.nearest);
        EXPECT_EQ(o.hausdorff, f.hausdorff);
        EXPECT_EQ(o.aToB.queryIndex, f.aToB.queryIndex);
        EXPECT_EQ(o.bToA.targetIndex, f.bToA.targetIndex);
    };
    auto f = engine->compute(c.a, c.b, full);
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ(f->aNearest.distance, oracle::bruteForceNearest(c.a, c.b));
    auto o = engine->compute(c.a, c.b, only);
    ASSERT_TRUE(o.ok()) << o.error().message;
    expectSame(*o, *f);
    {
        SCOPED_TRACE("recycled");
        HausdorffResult spent = *f;  // arrays of the right sizes, distances filled
        engine->recycle(std::move(spent));
        auto again = engine->compute(c.a, c.b, only);
        ASSERT_TRUE(again.ok()) << again.error().message;
        expectSame(*again, *f);
    }
    {
        SCOPED_TRACE("prepared");
        auto pa = engine->prepare(c.a);
        auto pb = engine->prepare(c.b);
        ASSERT_TRUE(pa && pb);
        auto p = engine->compute(*pa, *pb, only);
        ASSERT_TRUE(p.ok()) << p.error().message;
        expectSame(*p, *f);
    }
    {
        SCOPED_TRACE("double input far from the origin");
        std::vector<glm::dvec3> da, db;
        for (const glm::vec3& v : c.a) da.push_back(glm::dvec3(v) + glm::dvec3(5.0e5, -2.0e5, 1.0e3));
        for (const glm::vec3& v : c.b) db.push_back(glm::dvec3(v) + glm::dvec3(5.0e5, -2.0e5, 1.0e3));
        auto fd = engine->compute(PointView(da), PointView(db), full);
        auto od = engine->compute(PointView(da), PointView(db), only);
        ASSERT_TRUE(fd.ok() && od.ok());
        expectSame(*od, *fd);
    }
}

// CallOptions::perPointReady: each computed direction handed back exactly
// once, with the very array the result returns and its final values, before
// compute() returns, the result the same as without it — one-shot with A
// smaller and larger than B (a GPU hands the larger back first, while it
// searches the other), directed only, prepared, double input, a pair split
// into pieces (out-of-core); refused without perPointNearestOnly; ignored by
// computeBatch.
TEST(CallOptions, PerPointReadyHandsEachDirectionBackOnce) {
    RTHDIST_REQUIRE_TEST_ENGINE(engine);
    EngineOptions budgetOptions = engineUnderTest();
    budgetOptions.memoryBudget = 1500 * api::kBytesPerPoint;
    auto pieces = Engine::create(budgetOptions);
    ASSERT_TRUE(pieces.ok()) << pieces.error().message;
    const std::vector<glm::vec3> small = randomCloud(2000, 25);
    const std::vector<glm::vec3> large = randomCloud(5000, 26, glm::vec3(0.2f, 0.0f, 0.1f));
    struct Handed {
        int calls = 0;
        const uint32_t* data = nullptr;
        std::vector<uint32_t> values;
        bool besideCaller = false;  // called on another thread than compute()'s
    };
    using Run = std::function<Result<HausdorffResult>(const CallOptions&)>;
    auto expectHandedBack = [](const Run& run, bool directed) {
        CallOptions plain;
        plain.perPointDistances = plain.perPointNearestOnly = true;
        plain.directedOnly = directed;
        std::array<Handed, 2> handed;
        int other = 0;
        CallOptions call = plain;
        const std::thread::id caller = std::this_thread::get_id();
        call.perPointReady = [&](int k, std::span<const uint32_t> nearest) {
            if (k != 0 && k != 1) {
                ++other;
                return;
            }
            Handed& h = handed[size_t(k)];
            ++h.calls;
            h.data = nearest.data();
            h.values.assign(nearest.begin(), nearest.end());
            h.besideCaller = std::this_thread::get_id() != caller;
        };
        auto with = run(call);
        auto without = run(plain);
        ASSERT_TRUE(with.ok()) << with.error().message;
        ASSERT_TRUE(without.ok()) << without.error().message;
        EXPECT_EQ(other, 0);
        EXPECT_EQ(handed[0].calls, 1);
        EXPECT_EQ(handed[1].calls, directed ? 0 : 1);
        const std::array<const PerPoint*, 2> got = {&with->aNearest, &without->aNearest};
        const std::array<const PerPoint*, 2> gotB = {&with->bNearest, &without->bNearest};
        for (size_t k = 0; k < (directed ? 1u : 2u); ++k) {
            const PerPoint& w = k == 0 ? *got[0] : *gotB[0];
            const PerPoint& wo = k == 0 ? *got[1] : *gotB[1];
            EXPECT_EQ(handed[k].data, w.nearest.data()) << "direction " << k;
            EXPECT_EQ(handed[k].values, w.nearest) << "direction " << k;
            EXPECT_EQ(w.nearest, wo.nearest) << "direction " << k;
        }
        EXPECT_EQ(with->hausdorff, without->hausdorff);
        // Off the caller's thread: only on a GPU backend, only the first of
        // two directions, the one with more queries (A's on a tie).
        EXPECT_FALSE(handed[0].besideCaller && handed[1].besideCaller);
        if (with->backend == Backend::kCpu || directed) {
            EXPECT_FALSE(handed[0].besideCaller || handed[1].besideCaller);
        } else {
            const bool bLarger = with->bNearest.nearest.size() > with->aNearest.nearest.size();
            EXPECT_FALSE(handed[bLarger ? 0 : 1].besideCaller) << "the larger direction is handed back first";
        }
    };
    for (bool directed : {false, true}) {
        for (bool smallFirst : {true, false}) {
            const std::vector<glm::vec3>& a = smallFirst ? small : large;
            const std::vector<glm::vec3>& b = smallFirst ? large : small;
            SCOPED_TRACE(std::string(directed ? "directed" : "both") +
                         (smallFirst ? ", A smaller" : ", A larger"));
            {
                SCOPED_TRACE("one-shot");
                expectHandedBack([&](const CallOptions& c) { return engine->compute(a, b, c); }, directed);
            }
            {
                SCOPED_TRACE("prepared");
                auto pa = engine->prepare(a);
                auto pb = engine->prepare(b);
                ASSERT_TRUE(pa && pb);
                expectHandedBack([&](const CallOptions& c) { return engine->compute(*pa, *pb, c); },
                                 directed);
            }
            {
                SCOPED_TRACE("double input far from the origin");
                std::vector<glm::dvec3> da, db;
                for (const glm::vec3& v : a) da.push_back(glm::dvec3(v) + glm::dvec3(5.0e5, -2.0e5, 1.0e3));
                for (const glm::vec3& v : b) db.push_back(glm::dvec3(v) + glm::dvec3(5.0e5, -2.0e5, 1.0e3));
                expectHandedBack(
                    [&](const CallOptions& c) { return engine->compute(PointView(da), PointView(db), c); },
                    directed);
            }
            {
                SCOPED_TRACE("in pieces");
                expectHandedBack([&](const CallOptions& c) { return pieces->compute(a, b, c); }, directed);
            }
        }
    }
    CallOptions withDistances;
    withDistances.perPointDistances = true;
    withDistances.perPointReady = [](int, std::span<const uint32_t>) {};
    auto refused = engine->compute(small, large, withDistances);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(refused.error().message.find("perPointNearestOnly"), std::string::npos)
        << refused.error().message;
    auto ps = engine->prepare(small);
    auto pl = engine->prepare(large);
    ASSERT_TRUE(ps && pl);
    const std::array<PreparedSet, 2> sets = {*ps, *pl};
    const std::array<PairRef, 2> pairs = {PairRef{0, 1}, PairRef{1, 0}};
    CallOptions batch;
    batch.perPointDistances = batch.perPointNearestOnly = true;
    int batchCalls = 0;
    batch.perPointReady = [&](int, std::span<const uint32_t>) { ++batchCalls; };
    for (const Result<HausdorffResult>& r : engine->computeBatch(sets, pairs, batch))
        EXPECT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(batchCalls, 0);
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

// A planted symlink in the cache directory (issue 36): neither the old
// predictable temporary name (<file>.tmp<pid>) nor the file's own name is
// written through; a symlink at the file's name is not read, and is replaced
// by a regular file.
TEST(PipelineCache, PlantedSymlinksAreNeitherFollowedNorRead) {
    if (engineUnderTest().backend == Backend::kCpu) return;  // no pipeline cache
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("rthdist-cache-links-" + std::to_string(::getpid()));
    const fs::path victim = dir.string() + "-victim";
    fs::remove_all(dir);
    ASSERT_EQ(::mkdir(dir.c_str(), 0700), 0);
    std::ofstream(victim) << "precious";
    EngineOptions o = engineUnderTest();
    o.pipelineCacheDir = dir.string();
    auto engineStatus = [&o](std::string& path) {
        std::string whyNot;
        auto engine = makeEngine(o, whyNot);
        EXPECT_TRUE(engine) << whyNot;
        path = engine ? engine->pipelineCachePath() : "";
        return engine ? engine->pipelineCacheStatus() : whyNot;
    };
    std::string file;
    EXPECT_EQ(engineStatus(file), "none");
    ASSERT_TRUE(fs::is_regular_file(file));
    fs::remove(file);
    fs::create_symlink(victim, file + ".tmp" + std::to_string(::getpid()));
    EXPECT_EQ(engineStatus(file), "none");
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(file)));
    fs::remove(file);
    fs::create_symlink(victim, file);
    EXPECT_EQ(engineStatus(file).rfind("ignored: a symbolic link", 0), 0u);
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(file))) << "replaced by the new cache";
    std::ifstream in(victim);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "precious");
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.path().string().find(".tmp-") == std::string::npos;
    EXPECT_EQ(files, 2u) << "the cache and the planted .tmp<pid> link, no temporary left";
    fs::remove_all(dir);
    fs::remove(victim);
}

// A cache directory that another user can write is refused (nothing read or
// written) unless it is sticky and this user's.
TEST(PipelineCache, DirectoryOthersCanWriteIsRefused) {
    if (engineUnderTest().backend == Backend::kCpu) return;  // no pipeline cache
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("rthdist-cache-mode-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    ASSERT_EQ(::mkdir(dir.c_str(), 0700), 0);
    EngineOptions o = engineUnderTest();
    o.pipelineCacheDir = dir.string();
    for (const mode_t mode : {mode_t(0777), mode_t(0770), mode_t(0722), mode_t(01777), mode_t(0755)}) {
        SCOPED_TRACE("mode " + std::to_string(mode));
        ASSERT_EQ(::chmod(dir.c_str(), mode), 0);
        std::string whyNot;
        auto engine = makeEngine(o, whyNot);
        ASSERT_TRUE(engine) << whyNot;
        const bool refused = (mode & 022) != 0 && (mode & 01000) == 0;
        if (refused) {
            EXPECT_NE(engine->pipelineCacheStatus().find("can be written by other users"), std::string::npos)
                << engine->pipelineCacheStatus();
            EXPECT_EQ(engine->pipelineCachePath(), "");
            EXPECT_TRUE(fs::is_empty(dir));
        } else {
            EXPECT_TRUE(fs::is_regular_file(engine->pipelineCachePath())) << engine->pipelineCacheStatus();
        }
        for (const auto& e : fs::directory_iterator(dir)) fs::remove(e.path());
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace rthdist::test
