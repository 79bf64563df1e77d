// The CPU backend's batch search of the surface-to-surface refinement
// (cpu/sample_search.hpp): every sample's distance and nearest triangle
// equal the brute force's over every triangle, the returned index is the
// first largest, the same on any thread count; a set cancel flag is
// kCancelled.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <vector>

#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "core/point_triangle.hpp"
#include "cpu/sample_search.hpp"

namespace rthdist::cpu {
namespace {

TEST(BvhSampleSearch, EverySampleIsTheBruteForcesAndTheFirstLargestIsReturned) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        const MeshView mesh{PointView(c.vertices), c.indices};
        double magnitude = 0.0;
        for (const glm::dvec3& v : c.vertices)
            magnitude = std::max({magnitude, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
        for (const glm::dvec3& q : c.queries)
            magnitude = std::max({magnitude, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
        // A query repeated at the end: a tie for the largest only if it is the largest.
        std::vector<glm::dvec3> points = c.queries;
        points.push_back(c.queries.front());
        for (int threads : {1, 3}) {
            BvhSampleSearch search(mesh, core::closestSlack(magnitude), threads, nullptr);
            std::vector<double> distance(points.size());
            std::vector<uint32_t> nearest(points.size());
            Result<size_t> top = search.search(points, distance, nearest);
            ASSERT_TRUE(top) << c.name;
            size_t first = 0;
            for (size_t i = 0; i < points.size(); ++i) {
                const oracle::SurfaceNearest want =
                    oracle::bruteNearestTriangle(points[i], c.vertices, c.indices);
                EXPECT_EQ(distance[i], std::sqrt(want.distance2)) << c.name << " sample " << i;
                EXPECT_EQ(nearest[i], want.triangle) << c.name << " sample " << i;
                if (distance[i] > distance[first]) first = i;
            }
            EXPECT_EQ(*top, first) << c.name << ", " << threads << " threads";
        }
    }
}

TEST(BvhSampleSearch, ACancelledCallIsAnError) {
    const test::SurfaceCase c = test::heightField(3480, 4, 2.0);
    const MeshView mesh{PointView(c.vertices), c.indices};
    std::atomic<bool> cancel{true};
    BvhSampleSearch search(mesh, core::closestSlack(4.0), 1, &cancel);
    std::vector<glm::dvec3> points(300, glm::dvec3(0.5, 0.5, 3.0));
    std::vector<double> distance(points.size());
    std::vector<uint32_t> nearest(points.size());
    Result<size_t> top = search.search(points, distance, nearest);
    ASSERT_FALSE(top);
    EXPECT_EQ(top.error().code, ErrorCode::kCancelled);
}

}  // namespace
}  // namespace rthdist::cpu
