// The runs of a mesh (cpu/triangle_blocks.hpp): each run's box is exactly
// the smallest and largest corner coordinates of its triangles (runs of 64
// in input order, the last shorter), float and double vertices alike; and
// the witness check that skips runs (a kept mesh's search,
// cpu/surface_search.hpp) gives every surface case the answer of the check
// that reads every triangle, with and without the early break.
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/rng.hpp"
#include "common/surface_cases.hpp"
#include "cpu/surface_search.hpp"
#include "cpu/triangle_blocks.hpp"
#include "cpu/triangle_bvh.hpp"

namespace rthdist {
namespace {

constexpr size_t kRun = cpu::TriangleBlocks::kTriangles;

// Every run's box against its triangles' corners, read through the view.
void expectTightRuns(const MeshView& mesh, const cpu::TriangleBlocks& blocks, const char* what) {
    const size_t triangles = mesh.triangleCount();
    ASSERT_EQ(blocks.count(), (triangles + kRun - 1) / kRun) << what;
    for (size_t run = 0; run < blocks.count(); ++run) {
        glm::dvec3 lo(INFINITY), hi(-INFINITY);
        for (size_t t = run * kRun; t < std::min(triangles, (run + 1) * kRun); ++t) {
            for (int k = 0; k < 3; ++k) {
                lo = glm::min(lo, mesh.corner(t, k));
                hi = glm::max(hi, mesh.corner(t, k));
            }
        }
        EXPECT_EQ(blocks.lo(run), lo) << what << ", run " << run;
        EXPECT_EQ(blocks.hi(run), hi) << what << ", run " << run;
    }
}

TEST(TriangleBlocks, EachRunIsItsTrianglesBox) {
    test::Rng rng(5);
    for (const size_t triangles : {size_t(1), kRun - 1, kRun, kRun + 1, size_t(1000)}) {
        std::vector<glm::dvec3> vertices;
        for (size_t i = 0; i < triangles + 2; ++i)
            vertices.emplace_back(rng.uniform(-1e3, 1e3), rng.uniform(-1, 1), rng.uniform(5e6, 5.1e6));
        std::vector<uint32_t> indices;
        for (size_t i = 0; i < 3 * triangles; ++i) indices.push_back(uint32_t(rng.index(vertices.size())));
        const MeshView mesh{PointView(vertices), indices};
        for (const int threads : {1, 3}) expectTightRuns(mesh, cpu::TriangleBlocks(mesh, threads), "double");
        const std::vector<glm::vec3> floats(vertices.begin(), vertices.end());
        const MeshView floatMesh{PointView(floats), indices};
        expectTightRuns(floatMesh, cpu::TriangleBlocks(floatMesh, 2), "float");
    }
}

double magnitude(const test::SurfaceCase& c) {
    double m = 0.0;
    for (const auto* set : {&c.vertices, &c.queries}) {
        for (const glm::dvec3& v : *set) m = std::max({m, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    }
    return m;
}

TEST(TriangleBlocks, TheWitnessCheckSkippingRunsAnswersAsTheFullCheck) {
    std::vector<test::SurfaceCase> cases = test::makeSurfaceCases();
    // 7,200 triangles, queries above and beside them: many runs to skip.
    test::SurfaceCase field = test::heightField(12, 60, 10.0);
    test::Rng rng(13);
    for (int i = 0; i < 300; ++i)
        field.queries.emplace_back(rng.uniform(-2, 12), rng.uniform(-2, 12), rng.uniform(-1, 3));
    cases.push_back(std::move(field));
    for (test::SurfaceCase& c : cases) {
        const MeshView mesh{PointView(c.vertices), c.indices};
        const cpu::TriangleBvh bvh(mesh, 2);
        const cpu::TriangleBlocks blocks(mesh, 2);
        for (const bool perPoint : {false, true}) {
            SurfaceOptions options;
            options.perPointDistances = perPoint;
            options.threads = 2;
            const Result<SurfaceResult> all =
                cpu::surfaceSearch(PointView(c.queries), mesh, magnitude(c), options, bvh);
            const Result<SurfaceResult> runs =
                cpu::surfaceSearch(PointView(c.queries), mesh, magnitude(c), options, bvh, &blocks);
            ASSERT_TRUE(all.has_value()) << c.name << ": " << all.error().message;
            ASSERT_TRUE(runs.has_value()) << c.name << ": " << runs.error().message;
            EXPECT_EQ(runs->hausdorff, all->hausdorff) << c.name;
            EXPECT_EQ(runs->directed.queryIndex, all->directed.queryIndex) << c.name;
            EXPECT_EQ(runs->directed.triangle, all->directed.triangle) << c.name;
            EXPECT_EQ(runs->directed.surfacePoint, all->directed.surfacePoint) << c.name;
            EXPECT_EQ(runs->perPoint.distance, all->perPoint.distance) << c.name;
        }
    }
}

}  // namespace
}  // namespace rthdist
