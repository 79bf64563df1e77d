// The point-to-surface search's tree (src/gpu_algo/surface_tree.hpp) on the
// host, no device: every triangle in exactly one leaf, every box the exact
// float min/max of what lies below it, inner nodes' children adjacent, the
// stack bound of surface_tail.comp kept, and the same tree whatever the
// threads; on random soups, slivers, duplicates, triangles at one point and
// sizes around the leaf and chunk sizes.
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "core/float_box.hpp"
#include "gpu_algo/surface_tree.hpp"

namespace rthdist::gpu_algo {
namespace {

namespace sh = rthdist::shared;

using Box = core::FloatBox;

Box boxOf(const sh::Cell& c) { return {{c.lo.x, c.lo.y, c.lo.z}, {c.hi.x, c.hi.y, c.hi.z}}; }

// Random triangles in [-1, 1]^3: small ones, slivers (two corners equal or
// all three on a line), duplicates of earlier ones.
std::vector<glm::vec3> soup(size_t triangles, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), small(-0.01f, 0.01f);
    std::vector<glm::vec3> corners;
    for (size_t t = 0; t < triangles; ++t) {
        const glm::vec3 a(unit(rng), unit(rng), unit(rng));
        switch (t % 5) {
            case 0:
            case 1:
                corners.insert(corners.end(), {a, a + glm::vec3(small(rng), small(rng), small(rng)),
                                               a + glm::vec3(small(rng), small(rng), small(rng))});
                break;
            case 2: {  // a sliver: c on the line ab
                const glm::vec3 b = a + glm::vec3(small(rng), small(rng), small(rng));
                corners.insert(corners.end(), {a, b, a + 0.5f * (b - a)});
                break;
            }
            case 3:  // a point
                corners.insert(corners.end(), {a, a, a});
                break;
            default:  // a duplicate of the triangle before
                for (int k = 0; k < 3; ++k) corners.push_back(corners[corners.size() - 3]);
        }
    }
    return corners;
}

// Walks the whole tree from the root: every invariant of surface_tree.hpp.
void expectValid(const SurfaceTree& tree, std::span<const glm::vec3> corners) {
    const size_t triangles = corners.size() / 3;
    ASSERT_EQ(tree.order.size(), triangles);
    ASSERT_FALSE(tree.nodes.empty());
    ASSERT_GE(tree.levels, 1u);
    ASSERT_LE(tree.levels, kSurfaceTreeMaxLevels);
    std::vector<int> seen(triangles, 0);
    struct Entry {
        uint32_t node, depth;
    };
    std::vector<Entry> stack{{0u, 1u}};
    uint32_t deepest = 0;
    while (!stack.empty()) {
        const Entry e = stack.back();
        stack.pop_back();
        ASSERT_LT(e.node, tree.nodes.size());
        ASSERT_LE(e.depth, tree.levels);
        deepest = std::max(deepest, e.depth);
        const sh::Cell& n = tree.nodes[e.node];
        const Box box = boxOf(n);
        Box below;
        if (n.count > 0) {
            ASSERT_LE(n.count, kSurfaceTreeLeaf);
            ASSERT_LE(size_t(n.first) + n.count, triangles);
            for (uint32_t i = n.first; i < n.first + n.count; ++i) {
                const uint32_t t = tree.order[i];
                ASSERT_LT(t, triangles);
                ++seen[t];
                for (int k = 0; k < 3; ++k) below.add(corners[3 * size_t(t) + size_t(k)]);
            }
        } else {
            ASSERT_GT(n.first, e.node) << "children come after their parent";
            ASSERT_LT(size_t(n.first) + 1, tree.nodes.size());
            for (uint32_t c = n.first; c <= n.first + 1; ++c) {
                const Box child = boxOf(tree.nodes[c]);
                below.add(child.lo);
                below.add(child.hi);
                stack.push_back({c, e.depth + 1});
            }
        }
        // The exact min/max of the float corners below: it holds them, tightly.
        EXPECT_EQ(box.lo, below.lo) << "node " << e.node;
        EXPECT_EQ(box.hi, below.hi) << "node " << e.node;
    }
    // A path from the root passes at most `levels` nodes, so the shader's
    // stack (one entry per inner node passed) holds fewer.
    EXPECT_LE(deepest, tree.levels);
    for (size_t t = 0; t < triangles; ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
}

bool sameTree(const SurfaceTree& a, const SurfaceTree& b) {
    return a.levels == b.levels && a.order == b.order && a.nodes.size() == b.nodes.size() &&
           std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(sh::Cell)) == 0;
}

TEST(SurfaceTree, SmallSizesAroundTheLeaf) {
    for (size_t triangles : {1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 33, 100}) {
        const std::vector<glm::vec3> corners = soup(triangles, 11 + uint32_t(triangles));
        const SurfaceTree tree = buildSurfaceTree(corners, 1);
        SCOPED_TRACE(triangles);
        expectValid(tree, corners);
        if (triangles <= kSurfaceTreeLeaf) {
            EXPECT_EQ(tree.nodes.size(), 1u);  // the root is the one leaf
            EXPECT_EQ(tree.nodes[0].count, triangles);
        }
    }
}

TEST(SurfaceTree, ManyTrianglesOverSeveralChunksAndThreadCounts) {
    const std::vector<glm::vec3> corners = soup(100003, 5);
    const SurfaceTree one = buildSurfaceTree(corners, 1);
    expectValid(one, corners);
    for (int threads : {2, 3, 8, 0}) {
        const SurfaceTree many = buildSurfaceTree(corners, threads);
        EXPECT_TRUE(sameTree(one, many)) << threads << " threads";
    }
}

// Every centre at one point (no extent on any axis): one Morton code, the
// triangles' own order kept (ties by index).
TEST(SurfaceTree, EqualCentresKeepTheTrianglesOrder) {
    const glm::vec3 p(0.25f, -0.5f, 0.125f);
    std::vector<glm::vec3> corners;
    for (int t = 0; t < 50; ++t) {
        const float s = 0.001f * float(t);
        corners.insert(corners.end(), {p - glm::vec3(s), p, p + glm::vec3(s)});
    }
    const SurfaceTree tree = buildSurfaceTree(corners, 2);
    expectValid(tree, corners);
    for (uint32_t i = 0; i < tree.order.size(); ++i) EXPECT_EQ(tree.order[i], i);
}

// Triangles along a line in reverse order: the Morton order sorts them
// (leaves of neighbours), so the first leaf holds the last triangles.
TEST(SurfaceTree, LeavesHoldNeighbours) {
    std::vector<glm::vec3> corners;
    const int n = 64;
    for (int t = 0; t < n; ++t) {
        const float x = 1.0f - 2.0f * float(t) / float(n);
        corners.insert(corners.end(), {{x, 0, 0}, {x + 0.01f, 0, 0}, {x, 0.01f, 0}});
    }
    const SurfaceTree tree = buildSurfaceTree(corners, 1);
    expectValid(tree, corners);
    for (uint32_t i = 0; i < tree.order.size(); ++i) EXPECT_EQ(tree.order[i], uint32_t(n - 1) - i);
}

// Two clusters of 5 and 11 triangles: the root splits between them (the
// Morton codes' highest differing bit), so each child's box is one
// cluster's, not a box across the gap (pairing leaves of 4 over the sorted
// order would put 1 triangle of the first cluster with 3 of the second).
TEST(SurfaceTree, TheRootSplitsBetweenClusters) {
    std::vector<glm::vec3> corners;
    Box first, second;
    for (int t = 0; t < 16; ++t) {
        const glm::vec3 at = t < 5 ? glm::vec3(-1.0f + 0.01f * float(t)) : glm::vec3(1.0f - 0.01f * float(t));
        const glm::vec3 tri[3] = {at, at + glm::vec3(0.005f, 0, 0), at + glm::vec3(0, 0.005f, 0)};
        for (const glm::vec3& c : tri) (t < 5 ? first : second).add(c);
        corners.insert(corners.end(), std::begin(tri), std::end(tri));
    }
    const SurfaceTree tree = buildSurfaceTree(corners, 1);
    expectValid(tree, corners);
    ASSERT_EQ(tree.nodes[0].count, 0u);
    const Box left = boxOf(tree.nodes[tree.nodes[0].first]),
              right = boxOf(tree.nodes[tree.nodes[0].first + 1]);
    EXPECT_EQ(left.lo, first.lo);
    EXPECT_EQ(left.hi, first.hi);
    EXPECT_EQ(right.lo, second.lo);
    EXPECT_EQ(right.hi, second.hi);
}

// Triangles peeled off one by one by the Morton splits (centres at 2^-k of
// the box on each axis, 3 x 10 of them, each its own half of the cell
// before) above 8,192 triangles at one corner: uneven splits all the way
// would pass the descent's stack (30 levels of peeling, then 11 of equal
// codes); the depth guard splits in the middle instead, so the tree stays
// within kSurfaceTreeMaxLevels and valid.
TEST(SurfaceTree, DepthGuardHoldsUnevenSplits) {
    std::vector<glm::vec3> corners;
    const auto add = [&](glm::vec3 at) {
        corners.insert(corners.end(), {at, at + glm::vec3(1e-7f, 0, 0), at + glm::vec3(0, 1e-7f, 0)});
    };
    add(glm::vec3(1.0f));
    for (int k = 1; k <= 10; ++k) {
        const float x = std::ldexp(1.0f, -k);
        add({x, 0, 0});
        add({0, x, 0});
        add({0, 0, x});
    }
    for (int t = 0; t < 8192; ++t) add(glm::vec3(0.0f));
    const SurfaceTree tree = buildSurfaceTree(corners, 2);
    expectValid(tree, corners);
    EXPECT_LE(tree.levels, kSurfaceTreeMaxLevels);
    EXPECT_GT(tree.levels, 20u);  // the peeling did happen above the guard
}

}  // namespace
}  // namespace rthdist::gpu_algo
