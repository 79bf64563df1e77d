// The point-to-surface search on the GPU backends (issue 34; design.md §11,
// "The GPU backends"): hausdorffToSurface with the backend under test
// (RTHDIST_TEST_BACKEND) against the brute force over every triangle
// (tests/common) with ==, on every surface case (random soups, a height
// field, slivers, zero-area and duplicate triangles, points on the surface
// and on edges, far-apart and georeferenced inputs) and named degenerate
// inputs; the validation layer on and silent. The kept-device route
// (Engine::hausdorffToSurface): one Engine serving calls of growing and
// shrinking sizes equals the brute force and a one-shot call, a cancelled
// call leaves it usable, per-point distances stay refused.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <atomic>
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

MeshView meshOf(const test::SurfaceCase& c) { return MeshView{PointView(c.vertices), c.indices}; }

// r (of case c on `backend`) against the brute force over every triangle.
void expectBruteForce(const test::SurfaceCase& c, Backend backend, const Result<SurfaceResult>& r) {
    std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
    const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
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
    // The device searched: at least one radius, a ray per query at the first,
    // one submission per radius at most (the first holds the upload too).
    EXPECT_GE(n.radii, 1u) << c.name;
    EXPECT_GE(n.rays, c.queries.size()) << c.name;
    EXPECT_GE(n.submissions, 1u) << c.name;
    EXPECT_LE(n.submissions, n.radii) << c.name;
    // The proof searched the witness again, at least.
    EXPECT_GE(n.band, 1u) << c.name;
    EXPECT_LE(n.band, c.queries.size()) << c.name;
    EXPECT_EQ(r->validationMessages, 0u) << c.name;
    std::printf("  h %.17g: %u radii, %llu rays, %u submissions, band %llu\n", r->hausdorff, n.radii,
                static_cast<unsigned long long>(n.rays), n.submissions,
                static_cast<unsigned long long>(n.band));
}

void expectBruteForce(const test::SurfaceCase& c, Backend backend) {
    expectBruteForce(c, backend, onDevice(c, backend));
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

namespace rthdist {
namespace {

// The first oracle case with queries.
test::SurfaceCase firstCase() {
    for (test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (!c.queries.empty()) return c;
    }
    return {};
}

// The kept device's Engine, validation on (its messages counted over its life).
Result<Engine> surfaceEngine(Backend backend) {
    EngineOptions o;
    o.backend = backend;
    o.validation = true;
    return Engine::create(o);
}

// Larger and smaller inputs one after another on one Engine: its buffers
// grow and are reused for smaller calls; each result equals the brute
// force and the one-shot call's (value, witness and what the device did).
TEST(GpuSurfaceEngine, RepeatedCallsOfGrowingAndShrinkingSizesMatchAFreshDevice) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    Result<Engine> engine = surfaceEngine(backend);
    ASSERT_TRUE(engine) << engine.error().message;
    test::SurfaceCase big = test::heightField(3440, 40, 10.0);
    for (int i = 0; i < 1500; ++i)
        big.queries.emplace_back(0.1 + 0.0061 * i, 9.7 - 0.0059 * i, (i % 11) * 0.3 - 1.4);
    std::vector<test::SurfaceCase> sequence{test::heightField(3441, 3, 1.0), big};
    sequence.front().queries = {{0.5, 0.5, 1.0}, {0.1, 0.9, -0.5}};
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (!c.queries.empty()) sequence.push_back(c);
    }
    sequence.push_back(big);
    sequence.push_back(sequence.front());
    for (const test::SurfaceCase& c : sequence) {
        const Result<SurfaceResult> kept = engine->hausdorffToSurface(PointView(c.queries), meshOf(c));
        expectBruteForce(c, backend, kept);
        ASSERT_TRUE(kept);
        EXPECT_EQ(kept->buildMs, 0.0) << c.name << ": an Engine creates no device per call";
        const Result<SurfaceResult> fresh = onDevice(c, backend);
        ASSERT_TRUE(fresh) << c.name << ": " << fresh.error().message;
        EXPECT_EQ(kept->directed.distance, fresh->directed.distance) << c.name;
        EXPECT_EQ(kept->directed.queryIndex, fresh->directed.queryIndex) << c.name;
        EXPECT_EQ(kept->directed.triangle, fresh->directed.triangle) << c.name;
        EXPECT_EQ(kept->directed.surfacePoint, fresh->directed.surfacePoint) << c.name;
        EXPECT_EQ(kept->directed.counters.radii, fresh->directed.counters.radii) << c.name;
        EXPECT_EQ(kept->directed.counters.rays, fresh->directed.counters.rays) << c.name;
        EXPECT_EQ(kept->directed.counters.band, fresh->directed.counters.band) << c.name;
    }
}

// Point calls and surface calls share the Engine's BLAS storage: each
// builds its own, so they interleave.
TEST(GpuSurfaceEngine, PointCallsBetweenSurfaceCalls) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    Result<Engine> engine = surfaceEngine(backend);
    ASSERT_TRUE(engine) << engine.error().message;
    const test::SurfaceCase c = firstCase();
    expectBruteForce(c, backend, engine->hausdorffToSurface(PointView(c.queries), meshOf(c)));
    CallOptions call;
    call.directedOnly = true;
    Result<HausdorffResult> points = engine->compute(PointView(c.queries), PointView(c.vertices), call);
    ASSERT_TRUE(points) << points.error().message;
    Options cpu;
    cpu.backend = Backend::kCpu;
    cpu.directedOnly = true;
    Result<HausdorffResult> want = hausdorff(PointView(c.queries), PointView(c.vertices), cpu);
    ASSERT_TRUE(want) << want.error().message;
    EXPECT_EQ(points->hausdorff, want->hausdorff);
    expectBruteForce(c, backend, engine->hausdorffToSurface(PointView(c.queries), meshOf(c)));
}

// The cancel flag is read between the device's submissions (and by the
// proof): a cancelled call is kCancelled, and the Engine's next call is
// exact.
TEST(GpuSurfaceEngine, ACancelledCallLeavesTheEngineUsable) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    Result<Engine> engine = surfaceEngine(backend);
    ASSERT_TRUE(engine) << engine.error().message;
    test::SurfaceCase c = test::heightField(3442, 12, 1.0);
    for (int i = 0; i < 50; ++i) c.queries.emplace_back(0.02 * i, 0.5, 0.01);
    c.queries.emplace_back(-3e3, 4e3, 5e2);  // several submissions: the radius grows to it
    const std::atomic<bool> cancel{true};
    SurfaceCallOptions call;
    call.cancel = &cancel;
    Result<SurfaceResult> r = engine->hausdorffToSurface(PointView(c.queries), meshOf(c), call);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kCancelled) << r.error().message;
    expectBruteForce(c, backend, engine->hausdorffToSurface(PointView(c.queries), meshOf(c)));
}

// Per-point distances on the Engine's GPU backend: refused with the
// reason, as one-shot, never computed on the CPU in its place; the Engine
// serves the next call.
TEST(GpuSurfaceEngine, PerPointDistancesAreRefusedNotReplaced) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    Result<Engine> engine = surfaceEngine(backend);
    ASSERT_TRUE(engine) << engine.error().message;
    const test::SurfaceCase c = firstCase();
    SurfaceCallOptions call;
    call.perPointDistances = true;
    Result<SurfaceResult> r = engine->hausdorffToSurface(PointView(c.queries), meshOf(c), call);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("per-point distances to a surface"), std::string::npos)
        << r.error().message;
    expectBruteForce(c, backend, engine->hausdorffToSurface(PointView(c.queries), meshOf(c)));
}

// Bad input on the kept device: the same errors as one-shot, the Engine usable after.
TEST(GpuSurfaceEngine, BadInputIsReportedAndTheEngineServesOn) {
    RTHDIST_REQUIRE_SURFACE_DEVICE();
    Result<Engine> engine = surfaceEngine(backend);
    ASSERT_TRUE(engine) << engine.error().message;
    const test::SurfaceCase c = test::heightField(3443, 4, 1.0);
    std::vector<uint32_t> outOfRange = c.indices;
    outOfRange[4] = uint32_t(c.vertices.size());
    const std::vector<glm::dvec3> points{{0.5, 0.5, 1.0}};
    Result<SurfaceResult> r =
        engine->hausdorffToSurface(PointView(points), MeshView{PointView(c.vertices), outOfRange});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("triangle 1"), std::string::npos) << r.error().message;
    test::SurfaceCase good = c;
    good.queries = points;
    expectBruteForce(good, backend, engine->hausdorffToSurface(PointView(points), meshOf(good)));
}

}  // namespace
}  // namespace rthdist
