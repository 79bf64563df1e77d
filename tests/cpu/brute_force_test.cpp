// The oracle itself: hand-computed values and its tie rules.
#include <gtest/gtest.h>

#include <cmath>

#include "common/brute_force.hpp"

namespace rthdist::oracle {
namespace {

TEST(BruteForce, HandComputed) {
    const std::vector<glm::vec3> a{{0, 0, 0}, {3, 4, 0}};
    const std::vector<glm::vec3> b{{0, 0, 1}};
    const DirectedExact ab = bruteForceDirected(a, b);
    EXPECT_DOUBLE_EQ(ab.distance, std::sqrt(26.0));
    EXPECT_EQ(ab.queryIndex, 1u);
    EXPECT_EQ(ab.targetIndex, 0u);
    const DirectedExact ba = bruteForceDirected(b, a);
    EXPECT_DOUBLE_EQ(ba.distance, 1.0);
    EXPECT_EQ(ba.targetIndex, 0u);
}

TEST(BruteForce, TiesTakeSmallestIndices) {
    // Queries 1 and 2 both at distance 1 from their nearest; targets 0 and 1 tie for query 1.
    const std::vector<glm::vec3> q{{0, 0, 0}, {5, 1, 0}, {5, -1, 0}};
    const std::vector<glm::vec3> t{{5, 2, 0}, {5, 0, 0}, {0, 0, 0}};
    for (int threads : {1, 2, 3}) {
        const DirectedExact d = bruteForceDirected(q, t, threads);
        EXPECT_DOUBLE_EQ(d.distance, 1.0);
        EXPECT_EQ(d.queryIndex, 1u);
        EXPECT_EQ(d.targetIndex, 0u);
    }
}

TEST(BruteForce, NearestOfEveryQuery) {
    const std::vector<glm::vec3> q{{0, 0, 0}, {2, 0, 0}, {10, 0, 0}};
    const std::vector<glm::vec3> t{{1, 0, 0}, {4, 0, 0}};
    const std::vector<double> nn = bruteForceNearest(q, t, 2);
    ASSERT_EQ(nn.size(), 3u);
    EXPECT_DOUBLE_EQ(nn[0], 1.0);
    EXPECT_DOUBLE_EQ(nn[1], 1.0);
    EXPECT_DOUBLE_EQ(nn[2], 6.0);
}

TEST(BruteForce, ComputesInDouble) {
    // Coordinates near 1e7: the unit difference must survive.
    const std::vector<glm::vec3> q{{1e7f, 0, 0}};
    const std::vector<glm::vec3> t{{1e7f + 1.0f, 0, 0}};
    EXPECT_DOUBLE_EQ(bruteForceDirected(q, t).distance, 1.0);
}

}  // namespace
}  // namespace rthdist::oracle
