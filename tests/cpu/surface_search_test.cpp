// The CPU backend's point-to-surface search (cpu/surface_search.hpp, design.md
// §11) against the brute force over every triangle (tests/common): per-point
// distances, triangles, closest points and barycentric coordinates, and the
// directed maximum with its witness, all with ==, on every surface case;
// with and without the early break, on one thread and on several.
#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "cpu/surface_search.hpp"
#include "cpu/triangle_bvh.hpp"

namespace rthdist {
namespace {

double magnitude(const test::SurfaceCase& c) {
    double m = 0.0;
    for (const auto* set : {&c.vertices, &c.queries}) {
        for (const glm::dvec3& v : *set) m = std::max({m, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    }
    return m;
}

Result<SurfaceResult> search(const test::SurfaceCase& c, bool perPoint, int threads) {
    const MeshView mesh{PointView(c.vertices), c.indices};
    SurfaceOptions options;
    options.perPointDistances = perPoint;
    options.threads = threads;
    return cpu::surfaceSearch(PointView(c.queries), mesh, magnitude(c), options);
}

void expectDirectedMatches(const test::SurfaceCase& c, const SurfaceResult& r,
                           const oracle::SurfaceDirectedExact& want) {
    EXPECT_EQ(r.directed.distance, want.distance) << c.name;
    EXPECT_EQ(r.hausdorff, want.distance) << c.name;
    EXPECT_EQ(r.directed.queryIndex, want.queryIndex) << c.name;
    EXPECT_EQ(r.directed.triangle, want.nearest.triangle) << c.name;
    EXPECT_EQ(r.directed.surfacePoint, want.nearest.point) << c.name;
    EXPECT_EQ(r.directed.queryPoint, c.queries[want.queryIndex]) << c.name;
    EXPECT_EQ(glm::length(r.directed.queryPoint - r.directed.surfacePoint), r.directed.distance) << c.name;
    EXPECT_EQ(r.directed.counters.queries, c.queries.size());
    EXPECT_EQ(r.directed.counters.triangles, c.indices.size() / 3);
}

TEST(SurfaceSearch, EveryCaseMatchesTheBruteForce) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                    static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
        const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
        for (int threads : {1, 4}) {
            Result<SurfaceResult> early = search(c, false, threads);
            ASSERT_TRUE(early) << c.name << ": " << early.error().message;
            expectDirectedMatches(c, *early, want);
            EXPECT_TRUE(early->perPoint.distance.empty());

            Result<SurfaceResult> full = search(c, true, threads);
            ASSERT_TRUE(full) << c.name << ": " << full.error().message;
            expectDirectedMatches(c, *full, want);
            EXPECT_EQ(full->directed.counters.dominated, 0u);
            ASSERT_EQ(full->perPoint.distance.size(), c.queries.size());
            size_t wrong = 0;
            for (size_t i = 0; i < c.queries.size(); ++i) {
                const oracle::SurfaceNearest& n = want.perQuery[i];
                if (full->perPoint.distance[i] != std::sqrt(n.distance2) ||
                    full->perPoint.triangle[i] != n.triangle || full->perPoint.closest[i] != n.point ||
                    full->perPoint.barycentric[i] != n.barycentric) {
                    if (++wrong <= 3) ADD_FAILURE() << c.name << ": query " << i << " differs";
                }
            }
            EXPECT_EQ(wrong, 0u) << c.name;
        }
    }
}

TEST(SurfaceSearch, PointsOnTheSurfaceMeasureZero) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.name != "on_surface" && c.name != "georeferenced_on_surface") continue;
        Result<SurfaceResult> r = search(c, true, 0);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->hausdorff, 0.0) << c.name;
        for (size_t i = 0; i < c.queries.size(); ++i)
            ASSERT_EQ(r->perPoint.distance[i], 0.0) << c.name << " " << i;
    }
}

TEST(SurfaceSearch, DuplicateTrianglesTieToTheSmallestIndex) {
    // Triangle 0 and its copies 1 (shared indices) and 2 (copied coordinates).
    const std::vector<glm::dvec3> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<uint32_t> idx{3, 4, 5, 0, 1, 2, 0, 1, 2};
    const std::vector<glm::dvec3> q{{0.25, 0.25, 2}, {5, 5, 5}};
    const MeshView mesh{PointView(v), idx};
    Result<SurfaceResult> r = cpu::surfaceSearch(PointView(q), mesh, 5.0, SurfaceOptions{});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->directed.queryIndex, 1u);
    EXPECT_EQ(r->directed.triangle, 0u);
    EXPECT_EQ(r->directed.surfacePoint, glm::dvec3(0.5, 0.5, 0));
}

TEST(SurfaceSearch, OneTriangleOnePoint) {
    const std::vector<glm::dvec3> v{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const std::vector<uint32_t> idx{0, 1, 2};
    const std::vector<glm::dvec3> q{{1, 1, -3}};
    Result<SurfaceResult> r =
        cpu::surfaceSearch(PointView(q), MeshView{PointView(v), idx}, 4.0, SurfaceOptions{});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->hausdorff, 3.0);
    EXPECT_EQ(r->directed.surfacePoint, glm::dvec3(1, 1, 0));
    EXPECT_EQ(r->directed.barycentric, glm::dvec3(0.5, 0.25, 0.25));
}

TEST(SurfaceSearch, CancelledBeforeTheFirstChunk) {
    const test::SurfaceCase c = test::heightField(3414, 4, 4.0);
    const std::vector<glm::dvec3> q(1000, glm::dvec3(1, 1, 1));
    std::atomic<bool> cancel{true};
    SurfaceOptions options;
    options.cancel = &cancel;
    Result<SurfaceResult> r =
        cpu::surfaceSearch(PointView(q), MeshView{PointView(c.vertices), c.indices}, 4.0, options);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kCancelled);
}

TEST(TriangleBvh, BalancedOnManyDuplicateTriangles) {
    // 100,000 copies of one triangle (one Morton code): the split must still halve them
    // (leaves of 2 to kLeafTriangles triangles: fewer nodes than triangles).
    const std::vector<glm::dvec3> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    std::vector<uint32_t> idx;
    for (int i = 0; i < 100000; ++i) idx.insert(idx.end(), {0, 1, 2});
    const cpu::TriangleBvh bvh(MeshView{PointView(v), idx});
    EXPECT_EQ(bvh.triangleCount(), 100000u);
    EXPECT_LT(bvh.nodeCount(), 100000u);
    EXPECT_GE(bvh.nodeCount(), 2 * 100000u / cpu::kLeafTriangles - 1);
    const cpu::NearestTriangle n = bvh.nearest(glm::dvec3(0.25, 0.25, 1), 0.0);
    EXPECT_EQ(n.triangle, 0u);
    EXPECT_EQ(n.distance2, 1.0);
}

}  // namespace
}  // namespace rthdist
