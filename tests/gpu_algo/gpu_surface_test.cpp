// The point-to-surface search on the GPU backends (issue 34; design.md §11,
// "The GPU backends"): hausdorffToSurface with the backend under test
// (RTHDIST_TEST_BACKEND) against the brute force over every triangle
// (tests/common) with ==, on every surface case (random soups, a height
// field, slivers, zero-area and duplicate triangles, points on the surface
// and on edges, far-apart and georeferenced inputs) and named degenerate
// inputs; the validation layer on and silent.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "core/search_mutant.hpp"
#include "gpu_algo/gpu_test_support.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {
namespace {

// The backend's device, or why there is none (CI fails on the skip).
std::string whyNoDevice(Backend backend) {
    EngineOptions o;
    o.backend = backend;
    auto e = Engine::create(o);
    return e ? std::string() : e.error().message;
}

#define RTHDIST_REQUIRE_SURFACE_DEVICE()                            \
    const Backend backend = test::backendUnderTest();               \
    if (const std::string why = whyNoDevice(backend); !why.empty()) \
    GTEST_SKIP() << "no device for this backend: " << why

Result<SurfaceResult> onDevice(const test::SurfaceCase& c, Backend backend) {
    SurfaceOptions options;
    options.backend = backend;
    options.validation = true;
    return hausdorffToSurface(PointView(c.queries), MeshView{PointView(c.vertices), c.indices}, options);
}

void expectBruteForce(const test::SurfaceCase& c, Backend backend) {
    std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
    const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
    Result<SurfaceResult> r = onDevice(c, backend);
    ASSERT_TRUE(r) << c.name << ": " << r.error().message;
    EXPECT_EQ(r->backend, backend) << c.name;
    EXPECT_EQ(r->hausdorff, want.distance) << c.name;
    EXPECT_EQ(r->directed.distance, want.distance) << c.name;
    EXPECT_EQ(r->directed.queryIndex, want.queryIndex) << c.name;
    EXPECT_EQ(r->directed.triangle, want.nearest.triangle) << c.name;
    EXPECT_EQ(r->directed.surfacePoint, want.nearest.point) << c.name;
    EXPECT_EQ(r->directed.queryPoint, c.queries[want.queryIndex]) << c.name;
    EXPECT_EQ(glm::length(r->directed.queryPoint - r->directed.surfacePoint), r->directed.distance) << c.name;
    const SurfaceCounters& n = r->directed.counters;
    EXPECT_EQ(n.queries, c.queries.size()) << c.name;
    EXPECT_EQ(n.triangles, c.indices.size() / 3) << c.name;
    // The device searched: at least one radius, a ray per query at the first.
    EXPECT_GE(n.radii, 1u) << c.name;
    EXPECT_GE(n.rays, c.queries.size()) << c.name;
    // The proof searched the witness again, at least.
    EXPECT_GE(n.band, 1u) << c.name;
    EXPECT_LE(n.band, c.queries.size()) << c.name;
    EXPECT_EQ(r->validationMessages, 0u) << c.name;
    std::printf("  h %.17g: %u radii, %llu rays, band %llu\n", r->hausdorff, n.radii,
                static_cast<unsigned long long>(n.rays), static_cast<unsigned long long>(n.band));
}

TEST(GpuSurface, EveryCaseMatchesTheBruteForce) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (!c.queries.empty()) expectBruteForce(c, backend);
    }
}

// The float search finds each query's nearest triangle up to rounding: on
// a height field with queries off it, the band the host searches again is
// the witness and its near ties, not the queries.
TEST(GpuSurface, TheDeviceFindsTheNearestTriangles) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    test::SurfaceCase c = test::heightField(3430, 20, 10.0);
    for (int i = 0; i < 400; ++i) {
        const double u = double(i % 20) / 20.0, v = double(i / 20) / 20.0;
        c.queries.emplace_back(0.3 + 9.4 * u, 0.3 + 9.4 * v, (i % 7) * 0.5 - 1.5);
    }
    expectBruteForce(c, backend);
    Result<SurfaceResult> r = onDevice(c, backend);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_LT(r->directed.counters.band, c.queries.size() / 10);
}

TEST(GpuSurface, OneTriangleOnePoint) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    test::SurfaceCase c{
        "one_triangle", 3431, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {{0.25, 0.25, 2.0}}};
    expectBruteForce(c, backend);
}

// Every vertex and every query at one point: the union's box has no extent.
TEST(GpuSurface, EverythingAtOnePoint) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    const glm::dvec3 p(3.5, -2.25, 1e6);
    test::SurfaceCase c{"one_point", 3432, {p, p, p, p}, {0, 1, 2, 1, 2, 3}, {p, p, p}};
    expectBruteForce(c, backend);
}

// A query far past the surface's size: the radius grows to the union's
// diagonal, where every box holds every query.
TEST(GpuSurface, OneFarQueryBesideNearOnes) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    test::SurfaceCase c = test::heightField(3433, 12, 1.0);
    for (int i = 0; i < 50; ++i) c.queries.emplace_back(0.02 * i, 0.5, 0.01);
    c.queries.emplace_back(-3e3, 4e3, 5e2);
    expectBruteForce(c, backend);
}

// Duplicate triangles in reverse order: the smallest index wins the tie.
TEST(GpuSurface, TiesGoToTheSmallestTriangleAndQuery) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    test::SurfaceCase c{"ties", 3434, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {2, 1, 0, 0, 1, 2, 1, 2, 0}, {}};
    c.queries = {{0.2, 0.2, -1.0}, {0.2, 0.2, 1.0}, {0.1, 0.3, 1.0}, {0.2, 0.2, -1.0}};
    expectBruteForce(c, backend);
}

// A device search that misses every third triangle (core::searchMutant):
// queries settle on triangles that are not their nearest, or on none; the
// host's proof searches them again and the value is still the brute
// force's.
TEST(GpuSurface, AMissingSearchIsCaughtByTheProof) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    struct Mutant {
        Mutant() { core::searchMutant() = true; }
        ~Mutant() { core::searchMutant() = false; }
    };
    uint64_t clean = 0, missing = 0;
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        Result<SurfaceResult> r = onDevice(c, backend);
        ASSERT_TRUE(r) << c.name << ": " << r.error().message;
        clean += r->directed.counters.band;
        const Mutant mutant;
        expectBruteForce(c, backend);
        r = onDevice(c, backend);
        ASSERT_TRUE(r) << c.name << ": " << r.error().message;
        missing += r->directed.counters.band;
    }
    // The missed triangles showed: the proof searched more queries again.
    std::printf("band %llu with the mutant, %llu without\n", static_cast<unsigned long long>(missing),
                static_cast<unsigned long long>(clean));
    EXPECT_GT(missing, clean);
}

TEST(GpuSurface, PerPointDistancesAreRefusedNotReplaced) {
    const test::SurfaceCase c = test::heightField(3435, 4, 1.0);
    const std::vector<glm::dvec3> points{{0.5, 0.5, 1.0}};
    SurfaceOptions options;
    options.backend = test::backendUnderTest();
    options.perPointDistances = true;
    Result<SurfaceResult> r =
        hausdorffToSurface(PointView(points), MeshView{PointView(c.vertices), c.indices}, options);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("per-point distances to a surface"), std::string::npos)
        << r.error().message;
}

}  // namespace
}  // namespace rthdist
