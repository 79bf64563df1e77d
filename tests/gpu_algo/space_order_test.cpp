// Whether a set's points lie in space order (src/gpu_algo/space_order.hpp),
// on the host: points in no order are not; the same points in Morton order,
// or gathered by groups of cells as the out-of-core pieces gather them
// (input order within a group), are; sets below kMinSpaceOrderPoints never are.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "gpu_algo/space_order.hpp"

namespace rthdist::gpu_algo {
namespace {

std::vector<glm::vec3> cloud(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<glm::vec3> p(n);
    for (glm::vec3& v : p) v = glm::vec3(u(rng), u(rng), u(rng));
    return p;
}

// The points ordered by key >> shift, stably (input order within a group).
std::vector<glm::vec3> byGroups(const std::vector<glm::vec3>& p, const core::GridSpec& g, uint32_t shift) {
    std::vector<uint32_t> key(p.size()), order(p.size());
    for (size_t i = 0; i < p.size(); ++i) {
        key[i] = core::cellKey(glm::dvec3(p[i]), g) >> shift;
        order[i] = uint32_t(i);
    }
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key[a] < key[b]; });
    std::vector<glm::vec3> out(p.size());
    for (size_t i = 0; i < p.size(); ++i) out[i] = p[order[i]];
    return out;
}

TEST(SpaceOrder, PointsInNoOrderAreNot) {
    const std::vector<glm::vec3> p = cloud(kMinSpaceOrderPoints, 1);
    const core::GridSpec g = core::makeGrid(core::boundsOf(p), 8);
    EXPECT_FALSE(inSpaceOrder(p, g));
}

TEST(SpaceOrder, MortonOrderAndThePiecesGroupsAre) {
    const std::vector<glm::vec3> p = cloud(kMinSpaceOrderPoints, 2);
    const core::GridSpec g = core::makeGrid(core::boundsOf(p), 8);
    EXPECT_TRUE(inSpaceOrder(byGroups(p, g, 0), g));
    // 2^12 groups of 2^12 keys each: a piece's blocks (kBlockGroupBits).
    EXPECT_TRUE(inSpaceOrder(byGroups(p, g, 12), g));
    // 2^6 groups: too coarse to count.
    EXPECT_FALSE(inSpaceOrder(byGroups(p, g, 18), g));
}

TEST(SpaceOrder, SmallSetsAreNot) {
    const std::vector<glm::vec3> p = cloud(kMinSpaceOrderPoints - 1, 3);
    const core::GridSpec g = core::makeGrid(core::boundsOf(p), 8);
    EXPECT_FALSE(inSpaceOrder(byGroups(p, g, 0), g));
}

}  // namespace
}  // namespace rthdist::gpu_algo
