// Out-of-core (EngineOptions::memoryBudget, src/api/out_of_core.hpp): a
// forced budget of a few thousand points per call splits every larger pair
// into query chunks and target tiles; the results equal the unsplit call's
// and the brute force's, on the backend under test.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <tuple>

#include "api/out_of_core.hpp"
#include "common/brute_force.hpp"
#include "common/case_sample.hpp"
#include "common/oracle_cases.hpp"
#include "common/rng.hpp"
#include "common/scoped_mutant.hpp"
#include "engine_test_support.hpp"

namespace rthdist::test {
namespace {

// An Engine of the backend under test whose calls hold `points` points each
// (the test has made one of this backend already, so this one must work).
Engine budgetEngine(uint64_t points) {
    EngineOptions o = engineUnderTest();
    o.memoryBudget = points * api::kBytesPerPoint;
    auto engine = Engine::create(o);
    if (!engine) throw std::runtime_error("second Engine: " + engine.error().message);
    return std::move(engine.value());
}

// The split result against the unsplit one: the same distances (exactly on
// the CPU backend, whose ties are deterministic; within the oracle's
// tolerance on a GPU, whose cells order their points by atomics) and, on the
// CPU, the same witnesses wherever the distance is not 0 (a query with a copy
// in the other set may name any copy).
void expectSameAsUnsplit(const OracleCase& c, const HausdorffResult& split, const HausdorffResult& whole) {
    const bool cpu = whole.backend == Backend::kCpu;
    const double tol = cpu ? 0.0 : oracleTolerance(c.a, c.b, whole.hausdorff);
    EXPECT_NEAR(split.hausdorff, whole.hausdorff, tol);
    for (auto [s, w] : {std::pair{&split.aToB, &whole.aToB}, std::pair{&split.bToA, &whole.bToA}}) {
        EXPECT_NEAR(s->distance, w->distance, tol);
        if (!cpu || w->distance == 0.0) continue;
        EXPECT_EQ(s->queryIndex, w->queryIndex);
        EXPECT_EQ(s->targetIndex, w->targetIndex);
    }
    for (auto [s, w] :
         {std::pair{&split.aNearest, &whole.aNearest}, std::pair{&split.bNearest, &whole.bNearest}}) {
        ASSERT_EQ(s->distance.size(), w->distance.size());
        for (size_t i = 0; i < s->distance.size(); ++i) ASSERT_NEAR(s->distance[i], w->distance[i], tol) << i;
    }
    EXPECT_EQ(split.validationMessages, 0u);
}

// Every oracle case under a budget of a third of its points per call (at
// least 2): each direction of every case with more than a few points runs
// in several calls.
TEST(OutOfCore, OracleSuiteUnderAForcedBudget) {
    RTHDIST_REQUIRE_TEST_ENGINE(whole);
    uint64_t splitCases = 0;
    const size_t stride = caseStride();
    for (const OracleCase& c : sampledCases(makeOracleCases())) {
        SCOPED_TRACE(c.name + " seed " + std::to_string(c.seed));
        const uint64_t points = std::max<uint64_t>(2, (c.a.size() + c.b.size()) / 3);
        Engine split = budgetEngine(points);
        auto want = whole->compute(c.a, c.b);
        auto got = split.compute(c.a, c.b);
        ASSERT_TRUE(want) << want.error().message;
        ASSERT_TRUE(got) << got.error().message;
        expectMatchesOracle(c, *got);
        expectSameAsUnsplit(c, *got, *want);
        const Counters& ab = got->aToB.counters;
        const Counters& ba = got->bToA.counters;
        if (c.a.size() + c.b.size() > points)
            EXPECT_GT(uint64_t(ab.queryChunks) * ab.targetTiles * ba.queryChunks * ba.targetTiles, 1u);
        EXPECT_EQ(ab.queries, c.a.size());
        EXPECT_EQ(ba.queries, c.b.size());
        if (ab.targetTiles > 1 && ba.targetTiles > 1) ++splitCases;
    }
    EXPECT_GT(splitCases, 100u / stride);  // most cases split both sets
}

// Per-point distances and the directed form under a budget: every query's
// nearest distance as in the unsplit call, with tiles on both sides.
TEST(OutOfCore, PerPointAndDirectedUnderAForcedBudget) {
    RTHDIST_REQUIRE_TEST_ENGINE(whole);
    Engine split = budgetEngine(1500);
    const OracleCase c{"out-of-core-per-point", 31, randomCloud(5000, 31),
                       randomCloud(4000, 32, glm::vec3(0.3f, 0.0f, 0.1f))};
    for (bool directed : {false, true}) {
        CallOptions call;
        call.perPointDistances = true;
        call.directedOnly = directed;
        auto want = whole->compute(c.a, c.b, call);
        auto got = split.compute(c.a, c.b, call);
        ASSERT_TRUE(want && got);
        expectMatchesOracle(c, *got, directed);
        expectSameAsUnsplit(c, *got, *want);
        EXPECT_EQ(got->directedOnly, directed);
        EXPECT_EQ(got->bNearest.distance.empty(), directed);
        EXPECT_GT(got->aToB.counters.targetTiles, 1u);
        EXPECT_GT(got->aToB.counters.queryChunks, 1u);
        // Nearest only: the pieces still merge by their distances, the
        // result drops them.
        CallOptions nearestOnly = call;
        nearestOnly.perPointNearestOnly = true;
        auto only = split.compute(c.a, c.b, nearestOnly);
        ASSERT_TRUE(only.ok()) << only.error().message;
        EXPECT_TRUE(only->aNearest.distance.empty());
        EXPECT_EQ(only->aNearest.nearest, got->aNearest.nearest);
        EXPECT_EQ(only->hausdorff, got->hausdorff);
    }
}

// Many queries against a handful of targets, and the reverse: one tile and
// many chunks, many tiles and one chunk (the shape of 300M points against 3).
TEST(OutOfCore, ManyPointsAgainstThree) {
    RTHDIST_REQUIRE_TEST_ENGINE(whole);
    Engine split = budgetEngine(2000);
    const OracleCase c{
        "many-against-three",
        41,
        randomCloud(20000, 41),
        {glm::vec3(0.1f, 0.2f, 0.3f), glm::vec3(0.9f, 0.5f, 0.5f), glm::vec3(0.5f, 0.9f, 0.1f)}};
    auto got = split.compute(c.a, c.b);
    auto want = whole->compute(c.a, c.b);
    ASSERT_TRUE(got && want);
    expectMatchesOracle(c, *got);
    expectSameAsUnsplit(c, *got, *want);
    EXPECT_GT(got->aToB.counters.queryChunks, 1u);
    EXPECT_EQ(got->aToB.counters.targetTiles, 1u);
    EXPECT_LE(got->bToA.counters.queryChunks, 3u);  // the pieces holding B's three points
    EXPECT_GT(got->bToA.counters.targetTiles, 1u);
}

// A backend stand-in for computeInPieces: the brute force (both directions
// unless the call is directed), counting the calls and the queries sent
// (from every lane).
struct CountingBruteForce {
    std::atomic<uint64_t> calls = 0, queriesSent = 0;
    static void direction(std::span<const glm::vec3> q, std::span<const glm::vec3> t, bool perPoint,
                          Directed& out, PerPoint& nearest) {
        const oracle::DirectedExact d = oracle::bruteForceDirected(q, t, 1);
        out.distance = d.distance;
        out.queryIndex = d.queryIndex;
        out.targetIndex = d.targetIndex;
        out.counters.queries = q.size();
        if (!perPoint) return;
        for (const oracle::NearestExact& n : oracle::bruteForceNearestIndexed(q, t, 1)) {
            nearest.distance.push_back(n.distance);
            nearest.nearest.push_back(n.targetIndex);
        }
    }
    Result<HausdorffResult> operator()(std::span<const glm::vec3> q, std::span<const glm::vec3> t,
                                       const CallOptions& call) {
        ++calls;
        queriesSent += q.size();
        HausdorffResult r;
        r.directedOnly = call.directedOnly;
        direction(q, t, call.perPointDistances, r.aToB, r.aNearest);
        r.hausdorff = r.aToB.distance;
        if (!call.directedOnly) {
            queriesSent += t.size();
            direction(t, q, call.perPointDistances, r.bToA, r.bNearest);
            r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
        }
        return r;
    }
};

// The lattice {0..n-1}^3 in z-slab order, moved by `shift`.
std::vector<glm::vec3> slabLattice(int n, float shift) {
    std::vector<glm::vec3> p;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) p.push_back(glm::vec3(float(x), float(y), float(z)) + shift);
    return p;
}

// The points in a random order (Fisher-Yates).
void shuffle(std::vector<glm::vec3>& p, Rng& rng) {
    for (size_t i = p.size() - 1; i > 0; --i) std::swap(p[i], p[rng.index(i + 1)]);
}

// The pieces are cut in space whatever the input order: a lattice given in
// z-slab order and the same lattice shuffled each meet only the border
// layers of neighbouring pieces, so the calls send about each query once;
// once round one has settled the far outlier's maximum, the open queries
// near piece borders are dropped by the early break. The result is the
// brute force's, witnesses included, in both orders.
TEST(OutOfCore, PiecesInSpaceSendEachQueryAboutOnce) {
    const int n = 16;
    for (const bool shuffled : {false, true}) {
        SCOPED_TRACE(shuffled ? "shuffled" : "z-slab order");
        std::vector<glm::vec3> a = slabLattice(n, 0.0f);
        std::vector<glm::vec3> b = slabLattice(n, 0.5f);
        b.push_back(glm::vec3(40.25f, -3.5f, 7.125f));  // the outlier: h(B,A) is its
        if (shuffled) {
            Rng rng(7);
            shuffle(a, rng);
            shuffle(b, rng);
        }
        using Sets = const std::vector<glm::vec3>*;
        api::MemoryBudget budget;
        budget.bytes = 2 * 512 * api::kBytesPerPoint;  // pieces of at most 512 points of each set
        CountingBruteForce fake;
        const api::DirectedCall call = [&fake](int, auto q, auto t, const CallOptions& o,
                                               const core::PerPointFloor&) { return fake(q, t, o); };
        auto r = api::computeInPieces(a, b, 1.0, CallOptions{}, budget, call, {});
        ASSERT_TRUE(r) << r.error().message;
        for (auto [got, q, t] : {std::tuple<const Directed*, Sets, Sets>{&r->aToB, &a, &b},
                                 std::tuple<const Directed*, Sets, Sets>{&r->bToA, &b, &a}}) {
            const oracle::DirectedExact want = oracle::bruteForceDirected(*q, *t);
            EXPECT_EQ(got->distance, want.distance);
            EXPECT_EQ(got->queryIndex, want.queryIndex);
            EXPECT_EQ(got->targetIndex, want.targetIndex);
            EXPECT_GE(got->counters.queryChunks, 8u);  // 4097 points at most 512 a piece
            EXPECT_GE(got->counters.targetTiles, 8u);
            EXPECT_EQ(got->counters.queries, q->size());
            EXPECT_LT(got->counters.crossPieceQueries, q->size() / 4);
        }
        // Round one sends every point once (both directions in one call); the
        // queries sent again are those near a piece's border.
        EXPECT_LT(fake.queriesSent, 2u * (a.size() + b.size()));
        EXPECT_LT(fake.calls, 4u * 9u);
    }
}

// Per-point output through pieces in space: every query's nearest distance
// and index as the brute force's (the smaller index among equal distances),
// on a lattice whose queries sit at equal distances from several targets.
// Round two asks no call for the queries past their piece (few points of
// the other pieces can be near them: api/out_of_core.cpp scanOnHost): every
// call is a piece's round-one call.
TEST(OutOfCore, PiecesInSpaceBreakTiesByInputIndex) {
    std::vector<glm::vec3> a = slabLattice(10, 0.0f);
    std::vector<glm::vec3> b = slabLattice(10, 0.5f);
    Rng rng(11);
    shuffle(a, rng);
    shuffle(b, rng);
    api::MemoryBudget budget;
    budget.bytes = 2 * 128 * api::kBytesPerPoint;
    CountingBruteForce fake;
    const api::DirectedCall call = [&fake](int, auto q, auto t, const CallOptions& o,
                                           const core::PerPointFloor&) { return fake(q, t, o); };
    CallOptions options;
    options.perPointDistances = true;
    auto r = api::computeInPieces(a, b, 1.0, options, budget, call, {});
    ASSERT_TRUE(r) << r.error().message;
    for (auto [got, q, t] : {std::tuple{&r->aNearest, &a, &b}, std::tuple{&r->bNearest, &b, &a}}) {
        const std::vector<oracle::NearestExact> want = oracle::bruteForceNearestIndexed(*q, *t, 1);
        ASSERT_EQ(got->distance.size(), want.size());
        for (size_t i = 0; i < want.size(); ++i) {
            ASSERT_EQ(got->distance[i], want[i].distance) << i;
            ASSERT_EQ(got->nearest[i], want[i].targetIndex) << i;
        }
    }
    EXPECT_GT(r->aToB.counters.crossPieceQueries, 0u);  // border queries did go on
    EXPECT_GT(r->bToA.counters.crossPieceQueries, 0u);
    EXPECT_EQ(r->aToB.counters.queryChunks, r->bToA.counters.queryChunks);
    EXPECT_EQ(fake.calls.load(), uint64_t(r->aToB.counters.queryChunks));  // round one's calls only
}

// Round one's calls stop a query below a floor (core/per_point_floor.hpp)
// taken from queries known to be settled: the maximum settled so far and a
// sample whose nearest in its own piece is proven its nearest in the whole
// set (api/out_of_core.cpp seedFloor). Here every point of B is a point of
// A moved by 2-4 thousandths; a query near a piece's border has its partner
// in the next piece and its nearest in its own piece tens of times farther:
// a floor from such a query would stop the witness. The result is the brute
// force's.
TEST(OutOfCore, FloorsComeFromSettledQueriesOnly) {
    RTHDIST_REQUIRE_TEST_ENGINE(whole);
    Engine split = budgetEngine(2400);
    Rng rng(41);
    std::vector<glm::vec3> a = randomCloud(12000, 41), b;
    for (const glm::vec3& p : a) {
        const glm::dvec3 move = glm::dvec3(rng.gauss(), rng.gauss(), rng.gauss());
        b.push_back(glm::vec3(glm::dvec3(p) + (0.002 + 0.002 * rng.uniform()) * glm::normalize(move)));
    }
    shuffle(b, rng);
    const OracleCase c{"partners-across-pieces", 41, a, b};
    auto got = split.compute(c.a, c.b);
    ASSERT_TRUE(got) << got.error().message;
    expectMatchesOracle(c, *got);
    EXPECT_GT(got->aToB.counters.queryChunks, 4u);
}

// The pieces' proof takes each band query's candidates from the blocks near
// it (api/out_of_core.cpp addBandCandidates). Under a search that misses
// targets (core::searchMutant) round one's pairs are not all nearest: a
// band query's bound is then above its nearest, which must lie among its
// candidates for the proof to find it. Every value stays exact (a proof
// that fails is recomputed by the Engine), and some are recomputed. As in
// Certificate.MutantSearchIsCaughtAndRecomputed, the GPU's open queries go
// to the rays (whose refinement the mutant cuts short).
TEST(OutOfCore, MutantSearchIsCaughtByThePiecesProof) {
    RTHDIST_REQUIRE_TEST_ENGINE(whole);
    Tuning raysOnly;
    raysOnly.smallPairWork = 0;
    raysOnly.sweepWork = 0;
    raysOnly.tailScanWork = 0;
    raysOnly.tailScanStartWork = 0;
    uint64_t recomputed = 0, split = 0;
    const std::vector<OracleCase> cases = makeOracleCases();
    const test::ScopedSearchMutant mutant;
    for (size_t i = 0; i < cases.size(); i += 4) {
        const OracleCase& c = cases[i];
        if (c.a.size() + c.b.size() < 400) continue;
        SCOPED_TRACE(c.name + " seed " + std::to_string(c.seed));
        EngineOptions o = engineUnderTest();
        o.memoryBudget = std::max<uint64_t>(2, (c.a.size() + c.b.size()) / 3) * api::kBytesPerPoint;
        o.tuning = raysOnly;
        auto pieces = Engine::create(o);
        ASSERT_TRUE(pieces) << pieces.error().message;
        auto got = pieces->compute(c.a, c.b);
        ASSERT_TRUE(got) << got.error().message;
        expectMatchesOracle(c, *got);
        for (const Directed* d : {&got->aToB, &got->bToA}) recomputed += d->certificate.recomputed ? 1 : 0;
        split += got->aToB.counters.targetTiles > 1 ? 1 : 0;
    }
    std::printf("  the mutant's answers recomputed: %llu directions (%llu pairs in pieces)\n",
                static_cast<unsigned long long>(recomputed), static_cast<unsigned long long>(split));
    EXPECT_GT(split, 20u);
    EXPECT_GT(recomputed, 0u) << "the mutant never gave a wrong answer: the test tests nothing";
}

// Lanes (several devices) take a direction's chunks in parallel; the early
// break reads other lanes' witnesses, and ties go to the smallest query
// index: the result is the one-lane result, witnesses included, with tiles
// (a small budget) and without (one chunk per lane), per-point too.
TEST(OutOfCore, LanesGiveTheOneLaneResult) {
    const std::vector<glm::vec3> a = slabLattice(12, 0.0f);
    std::vector<glm::vec3> b = slabLattice(12, 0.5f);
    b.insert(b.begin() + 700, glm::vec3(-9.5f, 4.25f, 6.0f));  // h(B,A) witnessed inside a middle chunk
    b.push_back(glm::vec3(20.5f, 4.25f, 6.0f));                // and tied by the mirror outlier at the end
    CountingBruteForce fake;
    const api::DirectedCall call = [&fake](int, auto q, auto t, const CallOptions& o,
                                           const core::PerPointFloor&) { return fake(q, t, o); };
    for (uint64_t budgetPoints : {uint64_t(600), uint64_t(1) << 40}) {
        for (bool perPoint : {false, true}) {
            api::MemoryBudget budget;
            budget.bytes = budgetPoints * api::kBytesPerPoint;
            CallOptions options;
            options.perPointDistances = perPoint;
            auto one = api::computeInPieces(a, b, 1.0, options, budget, call, {}, 1);
            ASSERT_TRUE(one) << one.error().message;
            for (int lanes : {2, 3, 5}) {
                SCOPED_TRACE("budget " + std::to_string(budgetPoints) + " points, per-point " +
                             std::to_string(perPoint) + ", " + std::to_string(lanes) + " lanes");
                auto got = api::computeInPieces(a, b, 1.0, options, budget, call, {}, lanes);
                ASSERT_TRUE(got) << got.error().message;
                EXPECT_EQ(got->hausdorff, one->hausdorff);
                for (auto [g, w] : {std::pair{&got->aToB, &one->aToB}, std::pair{&got->bToA, &one->bToA}}) {
                    EXPECT_EQ(g->distance, w->distance);
                    EXPECT_EQ(g->queryIndex, w->queryIndex);
                    EXPECT_EQ(g->targetIndex, w->targetIndex);
                    EXPECT_GE(g->counters.queryChunks, uint32_t(lanes));
                }
                EXPECT_EQ(got->aNearest.nearest, one->aNearest.nearest);
                EXPECT_EQ(got->bNearest.distance, one->bNearest.distance);
            }
        }
    }
    // The outlier inserted at 700 is the witness: the first of the two ties.
    auto r = api::computeInPieces(a, b, 1.0, CallOptions{}, api::MemoryBudget{}, call, {}, 4);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->bToA.queryIndex, 700u);
    EXPECT_EQ(r->bToA.distance, oracle::bruteForceDirected(b, a).distance);
}

// A budget below two points is refused with the budget named, not run.
TEST(OutOfCore, BudgetBelowTwoPointsIsRefused) {
    EngineOptions o = engineUnderTest();
    o.memoryBudget = api::kBytesPerPoint;  // one point
    RTHDIST_REQUIRE_ENGINE(engine, o);
    auto r = engine->compute(randomCloud(10, 1), randomCloud(10, 2));
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kOutOfMemory);
    EXPECT_NE(r.error().message.find("memory budget of " + std::to_string(api::kBytesPerPoint)),
              std::string::npos)
        << r.error().message;
}

// The splitter's arithmetic: chunks and tiles within the budget and the
// largest piece, each direction covered.
TEST(OutOfCore, SplitStaysWithinTheBudget) {
    api::MemoryBudget budget;
    budget.bytes = 1000 * api::kBytesPerPoint;
    budget.maxPiecePoints = 300;
    for (uint64_t nq : {1u, 3u, 299u, 1000u, 123457u}) {
        for (uint64_t nt : {1u, 3u, 301u, 999u, 98765u}) {
            auto s = api::splitDirection(budget, nq, nt);
            ASSERT_TRUE(s);
            EXPECT_GE(s->queryChunk, 1u);
            EXPECT_GE(s->targetTile, 1u);
            EXPECT_LE(s->queryChunk, std::min<uint64_t>(nq, budget.maxPiecePoints));
            EXPECT_LE(s->targetTile, budget.maxPiecePoints);
            EXPECT_LE(s->queryChunk + s->targetTile, budget.pointsPerCall());
            if (nt <= 300) EXPECT_EQ(s->targetTile, nt);  // small targets stay whole
        }
    }
    // One call is tried whenever the bytes allow (a device may grant more
    // than maxMemoryAllocationSize); pieces stay within it.
    EXPECT_TRUE(api::fitsOneCall(budget, 300, 700));
    EXPECT_TRUE(api::fitsOneCall(budget, 999, 1));
    EXPECT_FALSE(api::fitsOneCall(budget, 300, 701));
}

}  // namespace
}  // namespace rthdist::test
