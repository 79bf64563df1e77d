// The automatic bit count (index_space.hpp, chooseBits) against a plain
// restatement of its rule: sample every stride-th target, count the distinct
// cells of each level with a set, extrapolate where the sample is thin. The
// library sorts the sample by radix and counts every level in one pass; both
// must pick the same k on every shape (uniform, surface-like, clustered,
// duplicated, flat, sizes around the sample's stride boundaries).
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "common/point_shapes.hpp"
#include "common/rng.hpp"
#include "core/index_space.hpp"

namespace rthdist::core {
namespace {

// The rule of design.md §5 written out directly (a set per level, no tricks).
int referenceBits(const std::vector<glm::vec3>& pts, const Bounds& b, double perCell = kTargetPointsPerCell) {
    const size_t n = pts.size();
    if (n <= 1) return kMinBits;
    const glm::dvec3 ext = b.hi - b.lo;
    const double longest = std::max({ext.x, ext.y, ext.z});
    if (!(longest > 0.0)) return kMinBits;
    const uint32_t axis = 1u << 10;
    const double cell = longest / double(axis);
    const size_t stride = std::max<size_t>(1, n / 32768);
    std::vector<uint32_t> keys;
    for (size_t i = 0; i < n; i += stride)
        keys.push_back(mortonEncode(cellCoord(pts[i].x, b.lo.x, cell, axis),
                                    cellCoord(pts[i].y, b.lo.y, cell, axis),
                                    cellCoord(pts[i].z, b.lo.z, cell, axis)));
    double estimate = 1.0, growth = 8.0;
    int chosen = kMinBits;
    for (int k = 1; k <= kMaxBits; ++k) {
        std::set<uint32_t> cells;
        for (uint32_t key : keys) cells.insert(key >> (3 * (10 - k)));
        double occupied = double(cells.size());
        if (double(keys.size()) / occupied >= 8.0 || stride == 1) {
            if (k > 1) growth = std::clamp(occupied / estimate, 1.0, 8.0);
        } else {
            occupied = estimate * growth;
        }
        estimate = occupied;
        if (double(n) / occupied < perCell) break;
        chosen = k;
    }
    return chosen;
}

Bounds boxOf(const std::vector<glm::vec3>& p) { return boundsOf(p); }

void expectSameBits(const std::vector<glm::vec3>& pts, const char* what) {
    const Bounds b = boxOf(pts);
    EXPECT_EQ(chooseBits(pts, b), referenceBits(pts, b)) << what << ", " << pts.size() << " points";
    EXPECT_EQ(chooseBits(pts, b, 2.0), referenceBits(pts, b, 2.0)) << what << " (2 per cell)";
}

TEST(ChooseBits, MatchesTheRuleOnUniformBoxesOfManySizes) {
    test::Rng rng(11);
    for (size_t n : {2u, 3u, 50u, 1000u, 32767u, 32768u, 32769u, 65537u, 200000u, 1000003u})
        expectSameBits(test::uniformBox(rng, n, {-1, -2, -3}, {4, 0.5, 1}), "uniform box");
}

TEST(ChooseBits, MatchesTheRuleOnSurfacesClustersAndFlatSets) {
    test::Rng rng(12);
    std::vector<glm::vec3> sphere(300000);
    for (glm::vec3& p : sphere) p = glm::vec3(rng.direction() * 5.0);
    expectSameBits(sphere, "sphere surface");
    expectSameBits(test::concat(test::uniformBox(rng, 100000, {0, 0, 0}, {1e-3, 1e-3, 1e-3}),
                                {glm::vec3(1700.0f, 0.0f, 0.0f)}),
                   "cluster with a far point");
    expectSameBits(test::uniformBox(rng, 70000, {0, 0, 2}, {10, 10, 2}), "flat");
    std::vector<glm::vec3> copies(40000, glm::vec3(1, 2, 3));
    copies.push_back(glm::vec3(2, 2, 3));
    expectSameBits(copies, "copies of one point and one other");
}

TEST(ChooseBits, DegenerateSetsTakeTheSmallestCount) {
    const std::vector<glm::vec3> one = {glm::vec3(1, 2, 3)};
    EXPECT_EQ(chooseBits(one, boxOf(one)), kMinBits);
    const std::vector<glm::vec3> same(1000, glm::vec3(4, 4, 4));
    EXPECT_EQ(chooseBits(same, boxOf(same)), kMinBits);
}

}  // namespace
}  // namespace rthdist::core
