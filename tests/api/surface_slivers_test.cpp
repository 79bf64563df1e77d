// The GPU route's slivers pass (api/surface_slivers.hpp) on the host, no
// device: per-point entries handed to it as a float search would leave them
// (a farther triangle for a point lying on a sliver) take the sliver's exact
// entry; entries no flagged triangle can beat stay as they are; a
// well-shaped mesh flags nothing.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

#include "api/surface_certify.hpp"
#include "api/surface_slivers.hpp"
#include "common/rng.hpp"
#include "core/point_triangle.hpp"

namespace rthdist {
namespace {

struct Mesh {
    std::vector<glm::dvec3> vertices;
    std::vector<uint32_t> indices;
    [[nodiscard]] MeshView view() const { return MeshView{PointView(vertices), indices}; }
    // The float corners as the device has them (the frame of scale 1).
    [[nodiscard]] std::vector<glm::vec3> corners() const {
        std::vector<glm::vec3> out;
        for (const uint32_t i : indices) out.emplace_back(vertices[i]);
        return out;
    }
};

// Entries as the proof leaves them for `triangle` of every query.
SurfacePerPoint entriesFor(const std::vector<glm::dvec3>& points, const Mesh& m,
                           std::vector<uint32_t> triangle) {
    SurfacePerPoint e;
    e.tolerance = 2.0 * api::kSearchedReach;
    for (size_t q = 0; q < points.size(); ++q) {
        const uint32_t t = triangle[q];
        const core::TriangleClosest c =
            core::closestOnTriangle(points[q], m.vertices[m.indices[3 * t]], m.vertices[m.indices[3 * t + 1]],
                                    m.vertices[m.indices[3 * t + 2]]);
        e.distance.push_back(std::sqrt(c.distance2));
        e.closest.push_back(c.point);
        e.barycentric.push_back(c.barycentric);
    }
    e.triangle = std::move(triangle);
    return e;
}

// Triangle 0 well shaped, 0.5 below the points; triangle 1 a sliver 0.8
// long and 1e-9 wide through the first point.
Mesh sliverMesh() {
    return Mesh{{{-0.5, -0.5, -0.5},
                 {0.5, -0.5, -0.5},
                 {0.0, 0.5, -0.5},  // 0
                 {-0.4, 0.0, 0.0},
                 {0.4, 0.0, 0.0},
                 {0.0, 1e-9, 0.0}},  // 1
                {0, 1, 2, 3, 4, 5}};
}

TEST(SurfaceSlivers, APointOnASliverTakesItsExactEntry) {
    const Mesh m = sliverMesh();
    const std::vector<glm::dvec3> points{{0.1, 0.0, 0.0}, {0.0, -0.3, -0.45}};
    // The device "found" triangle 0 for both (the sliver mismeasured).
    SurfacePerPoint e = entriesFor(points, m, {0, 0});
    const SurfacePerPoint before = e;
    const double h = std::max(e.distance[0], e.distance[1]);
    const std::vector<glm::vec3> corners = m.corners();
    EXPECT_EQ(api::measureSlivers(PointView(points), m.view(), corners, 1.0, h, 1.0, 2, e), 1u);
    const core::TriangleClosest onSliver =
        core::closestOnTriangle(points[0], m.vertices[3], m.vertices[4], m.vertices[5]);
    EXPECT_EQ(e.triangle[0], 1u);
    EXPECT_EQ(e.distance[0], std::sqrt(onSliver.distance2));
    EXPECT_LT(e.distance[0], 1e-9);
    EXPECT_EQ(e.closest[0], onSliver.point);
    EXPECT_EQ(e.barycentric[0], onSliver.barycentric);
    // The second point lies 0.05 above triangle 0, ~0.54 from the sliver: kept.
    const core::TriangleClosest second =
        core::closestOnTriangle(points[1], m.vertices[3], m.vertices[4], m.vertices[5]);
    ASSERT_GT(second.distance2, before.distance[1] * before.distance[1]);
    EXPECT_EQ(e.triangle[1], before.triangle[1]);
    EXPECT_EQ(e.distance[1], before.distance[1]);
}

// Distances only (SurfaceCallOptions::perPointDistancesOnly): no closest
// points to write.
TEST(SurfaceSlivers, DistancesOnlyEntriesAreMendedToo) {
    const Mesh m = sliverMesh();
    const std::vector<glm::dvec3> points{{-0.2, 0.0, 0.0}};
    SurfacePerPoint e = entriesFor(points, m, {0});
    e.closest.clear();
    e.barycentric.clear();
    const std::vector<glm::vec3> corners = m.corners();
    EXPECT_EQ(api::measureSlivers(PointView(points), m.view(), corners, 1.0, e.distance[0], 1.0, 1, e), 1u);
    EXPECT_EQ(e.triangle[0], 1u);
    EXPECT_TRUE(e.closest.empty());
}

// A well-shaped height field flags nothing and leaves every entry; many
// points far from a sliver keep theirs (the grid turns them away).
TEST(SurfaceSlivers, EntriesNoSliverCanBeatStay) {
    Mesh m;
    const int n = 20;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.vertices.emplace_back(-0.5 + double(i) / n, -0.5 + double(j) / n, 0.0);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = uint32_t(j * (n + 1) + i);
            m.indices.insert(m.indices.end(), {a, a + 1, a + uint32_t(n) + 1, a + 1, a + uint32_t(n) + 2,
                                               a + uint32_t(n) + 1});
        }
    test::Rng rng(3484);
    std::vector<glm::dvec3> points;
    std::vector<uint32_t> nearest;
    for (int q = 0; q < 2000; ++q) {
        points.emplace_back(rng.uniform(-0.45, 0.45), rng.uniform(-0.45, 0.45), rng.uniform(-0.01, 0.01));
        // Each point's own cell's first triangle: near, not always the nearest.
        const auto i = uint32_t((points.back().x + 0.5) * n), j = uint32_t((points.back().y + 0.5) * n);
        nearest.push_back(2 * (j * uint32_t(n) + i));
    }
    SurfacePerPoint e = entriesFor(points, m, nearest);
    const SurfacePerPoint before = e;
    double h = 0.0;
    for (const double d : e.distance) h = std::max(h, d);
    std::vector<glm::vec3> corners = m.corners();
    EXPECT_EQ(api::measureSlivers(PointView(points), m.view(), corners, 1.0, h, 1.0, 2, e), 0u);
    EXPECT_EQ(e.distance, before.distance);
    EXPECT_EQ(e.triangle, before.triangle);
    // A sliver far from every point (z = 0.4): flagged, beats no entry.
    const uint32_t v = uint32_t(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{-0.4, 0.0, 0.4}, {0.4, 0.0, 0.4}, {0.0, 1e-9, 0.4}});
    m.indices.insert(m.indices.end(), {v, v + 1, v + 2});
    corners = m.corners();
    EXPECT_EQ(api::measureSlivers(PointView(points), m.view(), corners, 1.0, h, 1.0, 2, e), 1u);
    EXPECT_EQ(e.distance, before.distance);
    EXPECT_EQ(e.triangle, before.triangle);
}

}  // namespace
}  // namespace rthdist
