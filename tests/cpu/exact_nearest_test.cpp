// Exact nearest neighbours in double (cpu/exact_nearest.hpp): the tree's
// answer equals a brute force over every target (core::exactDistance, the
// smallest index on a tie) from any start, on sets built to break float
// searches: a millimetre cluster beside strays kilometres away, lattices
// (ties everywhere), copies, points one double apart, float and double
// views; makePerPointExact mends wrong entries and keeps right ones.
#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "common/brute_force.hpp"
#include "common/rng.hpp"
#include "core/certificate.hpp"
#include "cpu/exact_nearest.hpp"

namespace rthdist::cpu {
namespace {

struct Case {
    std::string name;
    std::vector<glm::dvec3> targets, queries;
};

std::vector<Case> cases() {
    std::vector<Case> out;
    test::Rng rng(7001);
    {
        Case c{"a 1 mm cluster beside strays 1-3 km away", {}, {}};
        for (int i = 0; i < 3000; ++i)
            c.targets.emplace_back(rng.uniform(0, 1e-3), rng.uniform(0, 1e-3), rng.uniform(0, 1e-3));
        for (int i = 0; i < 4; ++i)
            c.targets.emplace_back(rng.uniform(1e3, 3e3), rng.uniform(1e3, 3e3), rng.uniform(-3e3, 3e3));
        for (int i = 0; i < 500; ++i)
            c.queries.emplace_back(rng.uniform(0, 1e-3), rng.uniform(0, 1e-3), rng.uniform(0, 1e-3));
        c.queries.emplace_back(2e3, 2e3, 0.0);
        out.push_back(c);
    }
    {
        Case c{"a lattice: every query ties", {}, {}};
        for (int x = 0; x < 12; ++x)
            for (int y = 0; y < 12; ++y)
                for (int z = 0; z < 12; ++z) c.targets.emplace_back(x * 0.25, y * 0.25, z * 0.25);
        for (int i = 0; i < 500; ++i)  // midpoints and cell centres: 2 to 8 equal targets
            c.queries.emplace_back(double(rng.index(23)) * 0.125, double(rng.index(23)) * 0.125,
                                   double(rng.index(23)) * 0.125);
        out.push_back(c);
    }
    {
        Case c{"copies: 40 points each repeated 50 times", {}, {}};
        std::vector<glm::dvec3> base;
        for (int i = 0; i < 40; ++i)
            base.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        for (int k = 0; k < 50; ++k)
            for (const glm::dvec3& b : base) c.targets.push_back(b);
        for (int i = 0; i < 300; ++i)
            c.queries.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        for (const glm::dvec3& b : base) c.queries.push_back(b);
        out.push_back(c);
    }
    {
        Case c{"points one double apart at UTM magnitudes", {}, {}};
        const glm::dvec3 o(512345.25, 5412345.5, 100.0);
        for (int i = 0; i < 2000; ++i) {
            const double ulp = std::nextafter(o.y, 1e300) - o.y;
            c.targets.push_back(o +
                                glm::dvec3(double(rng.index(64)) * ulp, double(rng.index(64)) * ulp, 0.0));
        }
        for (int i = 0; i < 300; ++i)
            c.queries.push_back(c.targets[rng.index(c.targets.size())] + glm::dvec3(1e-10, 0, 0));
        out.push_back(c);
    }
    {
        Case c{"one target", {{1, 2, 3}}, {{0, 0, 0}, {1, 2, 3}}};
        out.push_back(c);
    }
    return out;
}

TEST(ExactPointTree, NearestIsTheBruteForcesFromAnyStart) {
    for (const Case& c : cases()) {
        for (int threads : {1, 3}) {
            const ExactPointTree tree(PointView(c.targets), threads);
            test::Rng rng(7002);
            for (size_t i = 0; i < c.queries.size(); ++i) {
                const glm::dvec3& p = c.queries[i];
                const oracle::NearestExact want = oracle::bruteForceNearestInDouble(p, c.targets);
                const auto start = uint32_t(rng.index(c.targets.size()));
                const ExactPointTree::Nearest got =
                    tree.nearest(p, start, core::exactDistance(p, c.targets[start]));
                ASSERT_EQ(got.distance, want.distance) << c.name << ", query " << i;
                ASSERT_EQ(got.index, want.targetIndex)
                    << c.name << ", query " << i << ": the smallest index on a tie";
            }
        }
    }
}

// Past 2^12 points a level's ranges are built on several threads, and a
// level of fewer ranges than threads selects each range's median of 2^16 or
// more points on every thread (a sample's brackets, a three-way scatter):
// the same answers as the brute force on any thread count, for spread
// coordinates with copies, a lattice whose split axis holds four values
// only, points sorted along that axis, and a set whose evenly spaced sample
// lies far from its median (the selection's fallback).
TEST(ExactPointTree, AParallelBuildAnswersAsTheBruteForce) {
    test::Rng rng(7005);
    std::vector<std::vector<glm::dvec3>> sets(4);
    for (int i = 0; i < 150000; ++i)
        sets[0].emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.1, 0.1));
    for (int i = 0; i < 20000; ++i) sets[0].push_back(sets[0][rng.index(sets[0].size())]);  // copies
    for (int i = 0; i < 140000; ++i)
        sets[1].emplace_back(double(i % 4) * 0.6 - 0.9, rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.1));
    for (int i = 0; i < 140000; ++i)
        sets[2].emplace_back(-1.0 + 2.0 * i / 140000.0, rng.uniform(-0.2, 0.2), rng.uniform(-0.05, 0.05));
    for (int i = 0; i < 4096 * 40; ++i)  // the sample reads every 40th item: all at one end
        sets[3].emplace_back(i % 40 == 0 ? -1.0 : rng.uniform(-1, 1), rng.uniform(-1, 1),
                             rng.uniform(-0.1, 0.1));
    for (size_t s = 0; s < sets.size(); ++s) {
        const std::vector<glm::dvec3>& t = sets[s];
        for (int threads : {1, 4}) {
            const ExactPointTree tree(PointView(t), threads);
            test::Rng queries(7006);
            for (int i = 0; i < 60; ++i) {
                const glm::dvec3 p(queries.uniform(-1.2, 1.2), queries.uniform(-1.2, 1.2),
                                   queries.uniform(-0.2, 0.2));
                const oracle::NearestExact want = oracle::bruteForceNearestInDouble(p, t);
                const ExactPointTree::Nearest got = tree.nearest(p, 17, core::exactDistance(p, t[17]));
                ASSERT_EQ(got.distance, want.distance)
                    << "set " << s << ", " << threads << " threads, query " << i;
                ASSERT_EQ(got.index, want.targetIndex)
                    << "set " << s << ", " << threads << " threads, query " << i;
            }
        }
    }
}

TEST(ExactPointTree, FloatViewsAreTheirValuesInDouble) {
    test::Rng rng(7003);
    std::vector<glm::vec3> f;
    for (int i = 0; i < 5000; ++i)
        f.emplace_back(rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-1, 1));
    const std::vector<glm::dvec3> d(f.begin(), f.end());
    const ExactPointTree tree(PointView(f), 2);
    for (int i = 0; i < 300; ++i) {
        const glm::dvec3 p(rng.uniform(-11, 11), rng.uniform(-11, 11), rng.uniform(-2, 2));
        const oracle::NearestExact want = oracle::bruteForceNearestInDouble(p, d);
        const ExactPointTree::Nearest got = tree.nearest(p, 0, core::exactDistance(p, d[0]));
        ASSERT_EQ(got.distance, want.distance);
        ASSERT_EQ(got.index, want.targetIndex);
    }
}

// Entries from a search that picked a near but wrong target (here: every
// query's start is a random target, or its true nearest) become the brute
// force's; right ones stay; nearest-only arrays get the indices alone.
TEST(MakePerPointExact, MendsWrongEntriesAndKeepsRightOnes) {
    for (const Case& c : cases()) {
        test::Rng rng(7004);
        PerPoint pp;
        std::vector<oracle::NearestExact> want;
        uint64_t wrong = 0;
        for (const glm::dvec3& p : c.queries) {
            want.push_back(oracle::bruteForceNearestInDouble(p, c.targets));
            const bool keep = rng.index(2) == 0;
            const uint32_t start = keep ? want.back().targetIndex : uint32_t(rng.index(c.targets.size()));
            if (start != want.back().targetIndex) ++wrong;
            pp.nearest.push_back(start);
            pp.distance.push_back(core::exactDistance(p, c.targets[start]));
        }
        PerPoint nearestOnly;
        nearestOnly.nearest = pp.nearest;
        EXPECT_EQ(makePerPointExact(pp, PointView(c.queries), PointView(c.targets), 2), wrong) << c.name;
        EXPECT_EQ(makePerPointExact(nearestOnly, PointView(c.queries), PointView(c.targets), 2), wrong)
            << c.name;
        EXPECT_TRUE(nearestOnly.distance.empty());
        for (size_t i = 0; i < c.queries.size(); ++i) {
            ASSERT_EQ(pp.nearest[i], want[i].targetIndex) << c.name << ", query " << i;
            ASSERT_EQ(pp.distance[i], want[i].distance) << c.name << ", query " << i;
            ASSERT_EQ(nearestOnly.nearest[i], want[i].targetIndex) << c.name << ", query " << i;
        }
    }
}

}  // namespace
}  // namespace rthdist::cpu
