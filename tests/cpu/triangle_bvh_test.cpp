// The CPU backend's triangle BVH (cpu/triangle_bvh.hpp): the tree's
// invariants (each triangle in exactly one leaf, boxes that hold what is
// below them, median splits), the same tree and the same query answers
// whatever the build's thread count, and those answers against the brute
// force over every triangle, on random meshes with degenerate and duplicate
// triangles.
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "core/point_triangle.hpp"
#include "cpu/triangle_bvh.hpp"

namespace rthdist {
namespace {

struct RandomMesh {
    std::string name;
    std::vector<glm::dvec3> vertices;
    std::vector<uint32_t> indices;

    [[nodiscard]] MeshView view() const { return MeshView{PointView(vertices), indices}; }
    [[nodiscard]] size_t triangleCount() const { return indices.size() / 3; }
};

// `triangles` triangles over vertices on a coarse lattice (so that box
// centres tie often), with every kind of degenerate one mixed in: repeated
// corners, collinear corners, exact duplicates and duplicates with their
// corners rotated.
RandomMesh randomMesh(uint64_t seed, size_t triangles) {
    test::Rng rng(seed);
    RandomMesh m;
    m.name = "seed " + std::to_string(seed) + ", " + std::to_string(triangles) + " triangles";
    const size_t vertexCount = std::max<size_t>(triangles / 2, 3);
    for (size_t i = 0; i < vertexCount; ++i) {
        m.vertices.emplace_back(std::floor(rng.uniform(0, 64)) * 0.25, std::floor(rng.uniform(0, 64)) * 0.25,
                                std::floor(rng.uniform(0, 8)) * 0.25);
    }
    // Three collinear vertices.
    const auto line = uint32_t(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{1, 1, 1}, {2, 2, 2}, {4, 4, 4}});
    const auto vertex = [&] { return uint32_t(rng.index(vertexCount)); };
    while (m.triangleCount() < triangles) {
        const size_t kind = rng.index(40);
        const size_t have = m.triangleCount();
        if (kind == 0 && have > 0) {  // an exact duplicate
            const size_t t = rng.index(have);
            for (int k = 0; k < 3; ++k) m.indices.push_back(m.indices[3 * t + size_t(k)]);
        } else if (kind == 1 && have > 0) {  // a duplicate, corners rotated
            const size_t t = rng.index(have);
            for (int k = 1; k <= 3; ++k) m.indices.push_back(m.indices[3 * t + size_t(k % 3)]);
        } else if (kind == 2) {  // a point: one vertex three times
            const uint32_t v = vertex();
            m.indices.insert(m.indices.end(), {v, v, v});
        } else if (kind == 3) {  // a segment: a repeated corner
            const uint32_t a = vertex(), b = vertex();
            m.indices.insert(m.indices.end(), {a, b, a});
        } else if (kind == 4 && rng.index(8) == 0) {  // zero area, distinct collinear corners
            m.indices.insert(m.indices.end(), {line, line + 2, line + 1});
        } else {
            m.indices.insert(m.indices.end(), {vertex(), vertex(), vertex()});
        }
    }
    return m;
}

// Many copies of one triangle: every centre ties, only the index orders them.
RandomMesh duplicateMesh(size_t triangles) {
    RandomMesh m;
    m.name = std::to_string(triangles) + " copies of one triangle";
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (size_t i = 0; i < triangles; ++i) m.indices.insert(m.indices.end(), {0, 1, 2});
    return m;
}

std::vector<glm::dvec3> queries(const RandomMesh& m, uint64_t seed, size_t count) {
    test::Rng rng(seed);
    std::vector<glm::dvec3> q;
    for (size_t i = 0; i < count; ++i) {
        switch (i % 3) {
            case 0: q.push_back(m.vertices[rng.index(m.vertices.size())]); break;  // on a corner
            case 1: q.emplace_back(rng.uniform(-2, 18), rng.uniform(-2, 18), rng.uniform(-2, 4)); break;
            default:  // on a lattice point: ties between triangles
                q.emplace_back(std::floor(rng.uniform(0, 64)) * 0.25, std::floor(rng.uniform(0, 64)) * 0.25,
                               std::floor(rng.uniform(0, 8)) * 0.25);
        }
    }
    return q;
}

bool boxHolds(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& innerLo,
              const glm::dvec3& innerHi) {
    return glm::all(glm::lessThanEqual(lo, innerLo)) && glm::all(glm::lessThanEqual(innerHi, hi));
}

// The positions a subtree covers: [first, end).
struct Covered {
    uint32_t first, end;
};

// Walks the tree from the root and checks every invariant the query relies
// on, and the build's shape: a leaf holds 1 to kLeafTriangles consecutive
// positions, a node's children split its positions in two runs (the middle
// for at most twice kLeafTriangles), no node deeper than the build's limit
// of 64 (the root's depth 1).
void expectTreeInvariants(const RandomMesh& m, const cpu::TriangleBvh& bvh) {
    const size_t n = m.triangleCount();
    const auto& nodes = bvh.nodes();
    const auto& order = bvh.triangleOrder();
    ASSERT_EQ(order.size(), n) << m.name;
    ASSERT_FALSE(nodes.empty()) << m.name;
    std::vector<int> nodeSeen(nodes.size(), 0), triangleSeen(n, 0), positionSeen(n, 0);
    const auto walk = [&](const auto& self, uint32_t at, uint32_t depth) -> Covered {
        EXPECT_LT(at, nodes.size()) << m.name;
        if (at >= nodes.size()) return {0, 0};
        EXPECT_EQ(++nodeSeen[at], 1) << m.name << ": node " << at << " reached twice";
        EXPECT_LE(depth, 64u) << m.name;
        const cpu::TriangleBvh::Node& node = nodes[at];
        if (node.count > 0 || n == 0) {
            EXPECT_LE(node.count, cpu::kLeafTriangles) << m.name;
            glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
            for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                EXPECT_LT(i, n) << m.name;
                if (i >= n) break;
                ++positionSeen[i];
                const uint32_t t = order[i];
                EXPECT_LT(t, n) << m.name;
                if (t >= n) break;
                ++triangleSeen[t];
                const glm::dvec3 c0 = m.view().corner(t, 0), c1 = m.view().corner(t, 1),
                                 c2 = m.view().corner(t, 2);
                const glm::dvec3 tLo = glm::min(glm::min(c0, c1), c2), tHi = glm::max(glm::max(c0, c1), c2);
                EXPECT_TRUE(boxHolds(node.lo, node.hi, tLo, tHi))
                    << m.name << ": leaf " << at << ", triangle " << t;
                lo = glm::min(lo, tLo);
                hi = glm::max(hi, tHi);
            }
            if (node.count > 0) {  // the tightest float box around the union of its triangles'
                for (int k = 0; k < 3; ++k) {
                    EXPECT_LE(double(node.lo[k]), lo[k]) << m.name;
                    EXPECT_GT(double(std::nextafter(node.lo[k], INFINITY)), lo[k]) << m.name;
                    EXPECT_GE(double(node.hi[k]), hi[k]) << m.name;
                    EXPECT_LT(double(std::nextafter(node.hi[k], -INFINITY)), hi[k]) << m.name;
                }
            }
            return {node.first, node.first + node.count};
        }
        EXPECT_LT(size_t(node.first) + 1, nodes.size()) << m.name;
        EXPECT_GT(node.first, at) << m.name << ": children come after their parent";
        if (size_t(node.first) + 1 >= nodes.size() || node.first <= at) return {0, 0};
        const cpu::TriangleBvh::Node& l = nodes[node.first];
        const cpu::TriangleBvh::Node& r = nodes[node.first + 1];
        EXPECT_TRUE(boxHolds(node.lo, node.hi, l.lo, l.hi)) << m.name << ": node " << at;
        EXPECT_TRUE(boxHolds(node.lo, node.hi, r.lo, r.hi)) << m.name << ": node " << at;
        EXPECT_EQ(node.lo, glm::min(l.lo, r.lo)) << m.name;
        EXPECT_EQ(node.hi, glm::max(l.hi, r.hi)) << m.name;
        const Covered left = self(self, node.first, depth + 1);
        const Covered right = self(self, node.first + 1, depth + 1);
        EXPECT_EQ(left.end, right.first) << m.name << ": node " << at << "'s children are two runs";
        const uint32_t count = right.end - left.first;
        EXPECT_GT(count, cpu::kLeafTriangles) << m.name << ": a split node of few triangles";
        if (count <= 2 * cpu::kLeafTriangles) EXPECT_EQ(left.end - left.first, count / 2) << m.name;
        return {left.first, right.end};
    };
    const Covered all = walk(walk, 0, 1);
    EXPECT_EQ(all.first, 0u) << m.name;
    EXPECT_EQ(all.end, n) << m.name;
    for (size_t i = 0; i < nodes.size(); ++i)
        EXPECT_EQ(nodeSeen[i], 1) << m.name << ": node " << i << " unreached";
    for (size_t i = 0; i < n; ++i) {
        EXPECT_EQ(triangleSeen[i], 1) << m.name << ": triangle " << i;
        EXPECT_EQ(positionSeen[i], 1) << m.name << ": BVH position " << i;
    }
}

// The pruning slack of the meshes and queries here (coordinates within 20).
double slack() { return core::closestSlack(20.0); }

std::vector<RandomMesh> meshes() {
    std::vector<RandomMesh> all;
    // Small sizes around the leaf size and its doubles; then sizes whose top
    // levels the build splits in parallel (from 2^16 items a split runs on
    // several threads itself: the root of 65537, the top two levels of 140000).
    uint64_t seed = 1;
    for (size_t n : {1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 100, 4097, 30000, 65537, 140000})
        all.push_back(randomMesh(seed++, n));
    all.push_back(duplicateMesh(20000));
    return all;
}

// The split follows space, not the count: 1,000 triangles near the origin
// and 3 far away split at the root into those two groups (a split at the
// median of the counts would put 501 and 502 on the sides, each box
// spanning the gap).
TEST(TriangleBvh, TheRootSplitsBetweenClusters) {
    RandomMesh m = randomMesh(77, 1000);
    const auto base = uint32_t(m.vertices.size());
    for (int k = 0; k < 3; ++k) {
        const double x = 1000.0 + 2.0 * k;
        m.vertices.insert(m.vertices.end(), {{x, 1000, 0}, {x + 1, 1000, 0}, {x, 1001, 0}});
        m.indices.insert(m.indices.end(), {base + 3 * k, base + 3 * k + 1, base + 3 * k + 2});
    }
    const cpu::TriangleBvh bvh(m.view(), 2);
    expectTreeInvariants(m, bvh);
    const auto& nodes = bvh.nodes();
    ASSERT_EQ(nodes[0].count, 0u);
    const cpu::TriangleBvh::Node& right = nodes[nodes[0].first + 1];
    EXPECT_GE(right.lo.x, 1000.0f) << "the far triangles' own subtree";
    const cpu::TriangleBvh::Node& left = nodes[nodes[0].first];
    EXPECT_LT(left.hi.x, 100.0f);
}

TEST(TriangleBvh, TreeInvariantsOnRandomMeshes) {
    for (const RandomMesh& m : meshes()) {
        for (int threads : {1, 4}) {
            const cpu::TriangleBvh bvh(m.view(), threads);
            expectTreeInvariants(m, bvh);
        }
    }
}

TEST(TriangleBvh, SameTreeAndAnswersOnAnyThreadCount) {
    for (const RandomMesh& m : meshes()) {
        const cpu::TriangleBvh one(m.view(), 1);
        const std::vector<glm::dvec3> q =
            queries(m, 1000 + m.triangleCount(), m.triangleCount() > 10000 ? 60 : 300);
        for (int threads : {2, 8}) {
            const cpu::TriangleBvh many(m.view(), threads);
            ASSERT_EQ(many.nodeCount(), one.nodeCount()) << m.name << ", " << threads << " threads";
            EXPECT_EQ(many.triangleOrder(), one.triangleOrder()) << m.name << ", " << threads << " threads";
            for (size_t i = 0; i < one.nodeCount(); ++i) {
                const cpu::TriangleBvh::Node &a = one.nodes()[i], &b = many.nodes()[i];
                ASSERT_TRUE(a.lo == b.lo && a.hi == b.hi && a.first == b.first && a.count == b.count)
                    << m.name << ", " << threads << " threads: node " << i;
            }
            for (const glm::dvec3& p : q) {
                for (double stopBelow2 : {0.0, 0.5}) {
                    const cpu::NearestTriangle x = one.nearest(p, slack(), stopBelow2);
                    const cpu::NearestTriangle y = many.nearest(p, slack(), stopBelow2);
                    EXPECT_EQ(x.distance2, y.distance2) << m.name;
                    EXPECT_EQ(x.triangle, y.triangle) << m.name;
                    EXPECT_EQ(x.point, y.point) << m.name;
                    EXPECT_EQ(x.barycentric, y.barycentric) << m.name;
                    EXPECT_EQ(x.dominated, y.dominated) << m.name;
                    EXPECT_EQ(x.nodesVisited, y.nodesVisited) << m.name;
                    EXPECT_EQ(x.trianglesTested, y.trianglesTested) << m.name;
                }
            }
        }
    }
}

TEST(TriangleBvh, NearestEqualsTheBruteForceOnRandomMeshes) {
    for (const RandomMesh& m : meshes()) {
        if (m.triangleCount() > 30000) continue;  // the brute force is slow
        const cpu::TriangleBvh bvh(m.view(), 4);
        for (const glm::dvec3& p : queries(m, 7 + m.triangleCount(), 100)) {
            const oracle::SurfaceNearest want = oracle::bruteNearestTriangle(p, m.vertices, m.indices);
            const cpu::NearestTriangle got = bvh.nearest(p, slack());
            EXPECT_FALSE(got.dominated);
            EXPECT_EQ(got.distance2, want.distance2) << m.name;
            EXPECT_EQ(got.triangle, want.triangle) << m.name << ": the smallest index on a tie";
            EXPECT_EQ(got.point, want.point) << m.name;
        }
    }
}

// A hint (where an earlier query ended: its triangle, then for an early
// break its subtree) changes the work only: with any hint, from the
// previous query's answer to positions and nodes at random and past the
// arrays, the answer is the brute force's, and an early break stops at a
// real triangle's measure below the stop, and only when the brute force's
// nearest lies below it too.
TEST(TriangleBvh, AnyHintGivesTheBruteForcesAnswer) {
    for (const RandomMesh& m : meshes()) {
        if (m.triangleCount() > 30000) continue;  // the brute force is slow
        const cpu::TriangleBvh bvh(m.view(), 4);
        test::Rng rng(m.triangleCount());
        std::vector<uint32_t> positionOf(m.triangleCount());
        for (uint32_t i = 0; i < positionOf.size(); ++i) positionOf[bvh.triangleOrder()[i]] = i;
        cpu::TriangleHint previous;
        size_t hinted = 0, brokenByHint = 0;
        for (const glm::dvec3& p : queries(m, 11 + m.triangleCount(), 150)) {
            const oracle::SurfaceNearest want = oracle::bruteNearestTriangle(p, m.vertices, m.indices);
            const uint32_t n = uint32_t(bvh.nodeCount()), t = uint32_t(m.triangleCount());
            // The last hint is the nearest triangle itself: it ends every
            // early break at once.
            const cpu::TriangleHint hints[] = {previous,
                                               {uint32_t(rng.index(t)), uint32_t(rng.index(n))},
                                               {t + uint32_t(rng.index(3)), n + uint32_t(rng.index(3))},
                                               {UINT32_MAX, 0u},
                                               {positionOf[want.triangle], uint32_t(rng.index(n))}};
            for (const cpu::TriangleHint& hint : hints) {
                const cpu::NearestTriangle got = bvh.nearest(p, slack(), 0.0, hint);
                EXPECT_FALSE(got.dominated);
                EXPECT_EQ(got.distance2, want.distance2) << m.name;
                EXPECT_EQ(got.triangle, want.triangle) << m.name << ": the smallest index on a tie";
                EXPECT_EQ(got.point, want.point) << m.name;
                ASSERT_LT(got.position, t) << m.name;
                EXPECT_EQ(bvh.triangleOrder()[got.position], got.triangle) << m.name;
                // An early break at a stop just above the nearest (always
                // possible) and at the nearest itself (never).
                const double above = std::nextafter(want.distance2, 1e300) * 1.5 + 1e-300;
                const cpu::NearestTriangle early = bvh.nearest(p, slack(), above, hint);
                EXPECT_TRUE(early.dominated) << m.name;
                EXPECT_LT(early.distance2, above) << m.name;
                ASSERT_LT(early.position, t) << m.name;
                EXPECT_EQ(bvh.triangleOrder()[early.position], early.triangle) << m.name;
                const uint32_t* corner = &m.indices[3 * size_t(early.triangle)];
                EXPECT_EQ(early.distance2,
                          core::closestOnTriangle(p, m.vertices[corner[0]], m.vertices[corner[1]],
                                                  m.vertices[corner[2]])
                              .distance2)
                    << m.name << ": the measure of the triangle it names";
                if (hint.position < t) ++hinted;
                if (early.nodesVisited == 0) ++brokenByHint;
                if (want.distance2 > 0.0) {
                    const cpu::NearestTriangle never = bvh.nearest(p, slack(), want.distance2, hint);
                    EXPECT_FALSE(never.dominated) << m.name;
                    EXPECT_EQ(never.triangle, want.triangle) << m.name;
                }
            }
            const cpu::NearestTriangle next = bvh.nearest(p, slack(), 0.0, previous);
            previous = {next.position, next.near};
        }
        EXPECT_GT(hinted, 0u) << m.name;
        if (m.triangleCount() > 1)
            EXPECT_GT(brokenByHint, 0u) << m.name << ": a hint that never ends a query";
    }
}

// Coordinates float cannot hold (the boxes are float, rounded outward):
// doubles between floats, a georeferenced offset, magnitudes past float's
// range and in its subnormal range. The tree's invariants hold and every
// answer equals the brute force.
TEST(TriangleBvh, FloatBoxesHoldWhatFloatCannot) {
    struct Frame {
        double scale, offset;
    };
    for (const Frame f :
         {Frame{1.0, 0.0}, Frame{1.0, 6.4e6}, Frame{1e45, 0.0}, Frame{1e45, -1e46}, Frame{1e-42, 0.0}}) {
        RandomMesh m = randomMesh(77, 3000);
        const std::vector<glm::dvec3> lattice = queries(m, 78, 150);
        test::Rng rng(79);
        const auto place = [&](const glm::dvec3& v) { return v * f.scale + f.offset; };
        for (glm::dvec3& v : m.vertices)
            v = place(
                v + glm::dvec3(rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3)));
        m.name += ", x " + std::to_string(f.scale) + " + " + std::to_string(f.offset);
        const cpu::TriangleBvh bvh(m.view(), 2);
        expectTreeInvariants(m, bvh);
        const double magnitude = std::abs(f.offset) + 20.0 * f.scale;
        for (const glm::dvec3& q : lattice) {
            const glm::dvec3 p = place(q);
            const oracle::SurfaceNearest want = oracle::bruteNearestTriangle(p, m.vertices, m.indices);
            const cpu::NearestTriangle got = bvh.nearest(p, core::closestSlack(magnitude));
            EXPECT_EQ(got.distance2, want.distance2) << m.name;
            EXPECT_EQ(got.triangle, want.triangle) << m.name;
        }
    }
}

// A float mesh keeps its corners in float (half the memory): the same tree
// and the same answers as the same values given in double, and the brute
// force's.
TEST(TriangleBvh, FloatMeshAnswersAsTheSameValuesInDouble) {
    for (const size_t triangles : {size_t(5000), size_t(70000)}) {
        const RandomMesh m = randomMesh(91 + triangles, triangles);
        test::Rng rng(93);
        std::vector<glm::vec3> fv;
        for (const glm::dvec3& v : m.vertices)  // off the lattice, rounded to float once
            fv.emplace_back(
                v + glm::dvec3(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)));
        const std::vector<glm::dvec3> dv(fv.begin(), fv.end());  // the same values
        const cpu::TriangleBvh f(MeshView{PointView(fv), m.indices}, 2);
        const cpu::TriangleBvh d(MeshView{PointView(dv), m.indices}, 2);
        EXPECT_LT(f.hostBytes(), d.hostBytes()) << m.name;
        ASSERT_EQ(f.nodeCount(), d.nodeCount()) << m.name;
        EXPECT_EQ(f.triangleOrder(), d.triangleOrder()) << m.name;
        for (size_t i = 0; i < f.nodeCount(); ++i) {
            const cpu::TriangleBvh::Node &a = f.nodes()[i], &b = d.nodes()[i];
            ASSERT_TRUE(a.lo == b.lo && a.hi == b.hi && a.first == b.first && a.count == b.count)
                << m.name << ": node " << i;
        }
        const RandomMesh same{m.name, dv, m.indices};
        for (const glm::dvec3& p : queries(same, 94, 200)) {
            const cpu::NearestTriangle x = f.nearest(p, slack());
            const cpu::NearestTriangle y = d.nearest(p, slack());
            EXPECT_EQ(x.distance2, y.distance2) << m.name;
            EXPECT_EQ(x.triangle, y.triangle) << m.name;
            EXPECT_EQ(x.point, y.point) << m.name;
            EXPECT_EQ(x.barycentric, y.barycentric) << m.name;
            if (triangles <= 5000) {
                const oracle::SurfaceNearest want = oracle::bruteNearestTriangle(p, dv, m.indices);
                EXPECT_EQ(x.distance2, want.distance2) << m.name;
                EXPECT_EQ(x.triangle, want.triangle) << m.name;
            }
        }
    }
}

}  // namespace
}  // namespace rthdist
