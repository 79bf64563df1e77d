// core::proveDirection (core/certificate.hpp) on bands built here: the
// proof's value and witness equal a brute force in double whatever the
// first batch, a host brute force starting at one query sends only the
// queries whose bound can still exceed the maximum, the batches double up
// to kBruteForceBatch, and a bad band fails instead of proving a value.
#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "core/certificate.hpp"

namespace rthdist::core {
namespace {

struct Sets {
    std::vector<glm::dvec3> queries, targets;
};

Sets randomSets(size_t nq, size_t nt, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Sets s;
    for (size_t i = 0; i < nq; ++i) s.queries.push_back({u(rng), u(rng), u(rng)});
    for (size_t i = 0; i < nt; ++i) s.targets.push_back({u(rng), u(rng), u(rng)});
    return s;
}

// Each query's nearest target in double (ties: the smaller index).
std::vector<BandNearest> nearestOf(const Sets& s) {
    std::vector<BandNearest> out(s.queries.size());
    for (size_t q = 0; q < s.queries.size(); ++q) {
        out[q].query = q;
        for (size_t t = 0; t < s.targets.size(); ++t)
            out[q].offer(t, exactDistance(s.queries[q], s.targets[t]));
    }
    return out;
}

// The band of every query within `width` of the largest nearest distance
// (a slack e of width / 2: the band is what lies within 2e of the maximum),
// each with `best` as its search's pair (the nearest, or a farther target
// where `loose`), in search units of scale 1.
DirectionBand bandOf(const std::vector<BandNearest>& nearest, double width, bool loose) {
    DirectionBand band;
    band.present = true;
    double top = 0.0;
    for (const BandNearest& n : nearest) top = std::max(top, n.distance);
    band.hf = top;
    band.slack = 0.5 * width;
    for (const BandNearest& n : nearest) {
        if (n.distance < top - width) continue;
        // A loose pair: the next target (an upper bound of the nearest, as a
        // search's best pair is); the nearest itself otherwise.
        const uint64_t best = loose && n.target + 1 < 500 ? n.target + 1 : n.target;
        band.queries.push_back({n.query, best});
    }
    return band;
}

struct Recorded {
    std::vector<size_t> batches;
};

BruteForce recording(const Sets& s, Recorded& rec) {
    const PointAt query = [&s](uint64_t i) { return s.queries[i]; };
    const PointAt target = [&s](uint64_t i) { return s.targets[i]; };
    BruteForce inner = hostBruteForce(query, target, s.targets.size(), 2);
    return [inner, &rec](std::span<BandNearest> batch) {
        rec.batches.push_back(batch.size());
        return inner(batch);
    };
}

DirectedProof prove(const Sets& s, const DirectionBand& band, size_t firstBatch, Recorded& rec) {
    const PointAt query = [&s](uint64_t i) { return s.queries[i]; };
    const PointAt target = [&s](uint64_t i) { return s.targets[i]; };
    return proveDirection(band, query, target, recording(s, rec), firstBatch);
}

TEST(ProveDirection, TheValueAndWitnessAreTheBruteForcesWhateverTheFirstBatch) {
    for (uint32_t seed = 1; seed <= 5; ++seed) {
        const Sets s = randomSets(400, 500, seed);
        const std::vector<BandNearest> nearest = nearestOf(s);
        const BandNearest& want =
            *std::max_element(nearest.begin(), nearest.end(), [](const BandNearest& a, const BandNearest& b) {
                return a.distance < b.distance || (a.distance == b.distance && a.query > b.query);
            });
        for (bool loose : {false, true}) {
            const DirectionBand band = bandOf(nearest, 0.2, loose);
            ASSERT_GT(band.queries.size(), 10u) << seed;
            for (size_t first : {size_t(1), size_t(3), kBruteForceBatch}) {
                Recorded rec;
                const DirectedProof p = prove(s, band, first, rec);
                ASSERT_TRUE(p.proven) << p.failure;
                EXPECT_EQ(p.query, want.query) << "seed " << seed << " first " << first;
                EXPECT_EQ(p.target, want.target) << "seed " << seed << " first " << first;
                EXPECT_EQ(p.distance, want.distance) << "seed " << seed << " first " << first;
                EXPECT_EQ(p.band, band.queries.size());
            }
        }
    }
}

TEST(ProveDirection, AHostBruteForceStartsAtOneQueryAndDoubles) {
    const Sets s = randomSets(400, 500, 7);
    const std::vector<BandNearest> nearest = nearestOf(s);
    // Exact pairs: the first query's bound is the maximum and no other bound
    // exceeds it, so one query is searched, once.
    {
        Recorded rec;
        const DirectedProof p = prove(s, bandOf(nearest, 0.2, false), kHostFirstBatch, rec);
        ASSERT_TRUE(p.proven) << p.failure;
        EXPECT_EQ(p.bruteForced, 1u);
        EXPECT_EQ(rec.batches, std::vector<size_t>{1});
        // The same band from a first batch of 64 searched many more.
        Recorded all;
        const DirectedProof q = prove(s, bandOf(nearest, 0.2, false), kBruteForceBatch, all);
        EXPECT_GT(q.bruteForced, p.bruteForced);
        EXPECT_EQ(q.distance, p.distance);
    }
    // Loose pairs over a wide band: bounds above the maximum for many
    // queries, so batches of 1, 2, 4, ... each at most kBruteForceBatch.
    {
        Recorded rec;
        const DirectedProof p = prove(s, bandOf(nearest, 1.0, true), kHostFirstBatch, rec);
        ASSERT_TRUE(p.proven) << p.failure;
        ASSERT_GE(rec.batches.size(), 3u);
        size_t expected = 1;
        for (size_t k = 0; k + 1 < rec.batches.size(); ++k) {
            EXPECT_EQ(rec.batches[k], expected) << "batch " << k;
            expected = std::min(2 * expected, kBruteForceBatch);
        }
        EXPECT_LE(rec.batches.back(), expected);
        size_t sum = 0;
        for (size_t b : rec.batches) sum += b;
        EXPECT_EQ(sum, p.bruteForced);
    }
}

TEST(ProveDirection, AMaximumNoQueryReachesFailsTheProof) {
    const Sets s = randomSets(200, 300, 11);
    const std::vector<BandNearest> nearest = nearestOf(s);
    DirectionBand band = bandOf(nearest, 0.2, false);
    band.slack = 1e-12;
    band.hf *= 1.01;  // a search that reported more than any query's nearest
    for (size_t first : {kHostFirstBatch, kBruteForceBatch}) {
        Recorded rec;
        const DirectedProof p = prove(s, band, first, rec);
        EXPECT_FALSE(p.proven);
        EXPECT_FALSE(p.failure.empty());
    }
}

}  // namespace
// The view form of the host brute force (it skips the square root of a pair
// no nearer than the chunk's best) answers as the PointAt form on float and
// double views with a stride, ties included: targets on a coarse grid put
// many at the same distance from a grid query, and the smaller index wins.
TEST(HostBruteForce, TheViewFormAnswersAsThePointAtFormTiesIncluded) {
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> cell(-4, 4);
    const size_t n = 100000;      // several chunks of the parallel scan
    std::vector<float> packed;    // x, y, z, padding: a 16-byte stride
    std::vector<double> doubles;  // x, y, z
    std::vector<glm::dvec3> points;
    for (size_t i = 0; i < n; ++i) {
        const glm::dvec3 p(cell(rng) * 0.25, cell(rng) * 0.25, cell(rng) * 0.25);
        points.push_back(p);
        packed.insert(packed.end(), {float(p.x), float(p.y), float(p.z), 0.0f});
        doubles.insert(doubles.end(), {p.x, p.y, p.z});
    }
    const std::vector<glm::dvec3> queries = {
        {0.0, 0.0, 0.0}, {0.125, 0.125, 0.0}, {3.0, -2.0, 1.0}, {0.1, 0.2, 0.3}, {-1.0, -1.0, -1.0}};
    const PointAt query = [&queries](uint64_t i) { return queries[i]; };
    const PointAt target = [&points](uint64_t i) { return points[i]; };
    auto run = [&](const BruteForce& bf) {
        std::vector<BandNearest> band(queries.size());
        for (size_t k = 0; k < band.size(); ++k) band[k].query = k;
        EXPECT_TRUE(bf(band));
        return band;
    };
    const std::vector<BandNearest> want = run(hostBruteForce(query, target, n, 3));
    for (const PointView& view :
         {PointView::floats(packed.data(), n, 16), PointView::doubles(doubles.data(), n)}) {
        const std::vector<BandNearest> got = run(hostBruteForce(query, view, 3));
        for (size_t k = 0; k < queries.size(); ++k) {
            EXPECT_EQ(got[k].target, want[k].target) << "query " << k;
            EXPECT_EQ(got[k].distance, want[k].distance) << "query " << k;
        }
    }
    // A tie really is decided by index here: the origin's nearest is one of many at distance 0.
    EXPECT_EQ(want[0].distance, 0.0);
    EXPECT_EQ(want[0].target,
              size_t(std::find(points.begin(), points.end(), glm::dvec3(0.0)) - points.begin()));
}

}  // namespace rthdist::core
