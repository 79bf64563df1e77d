// The public point-to-surface call (rthdist/surface.hpp) on the CPU backend
// (the GPU backends: tests/gpu_algo/gpu_surface_test.cpp):
// float and double inputs of any stride against the brute force over every
// triangle, and every refusal as an Error value naming the set, the vertex
// or the triangle; Engine::hausdorffToSurface on an Engine of the CPU
// backend (kCpu, and kAuto where no RT hardware is) as the free function.
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {
namespace {

struct Small {
    std::vector<glm::dvec3> vertices{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {4, 4, 0}};
    std::vector<uint32_t> indices{0, 1, 2, 1, 3, 2};
    std::vector<glm::dvec3> points{{1, 1, 2}, {3, 3, -1}, {8, 4, 3}};
    [[nodiscard]] MeshView mesh() const { return MeshView{PointView(vertices), indices}; }
};

TEST(SurfaceApi, AutoAndCpuRunTheCpuBackend) {
    const Small s;
    for (Backend backend : {Backend::kAuto, Backend::kCpu}) {
        SurfaceOptions options;
        options.backend = backend;
        Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh(), options);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->backend, Backend::kCpu);
        EXPECT_EQ(r->device, "cpu");
        EXPECT_EQ(r->hausdorff, 5.0);  // (8, 4, 3) to the corner edge (4, 4, 0)
        EXPECT_EQ(r->directed.queryIndex, 2u);
        EXPECT_EQ(r->directed.surfacePoint, glm::dvec3(4, 4, 0));
    }
}

// The call on `engine` and the free function on the CPU backend, both with
// per-point distances: the same answers (==). Returns the Engine's result.
std::optional<SurfaceResult> engineEqualsFreeFunction(Engine& engine, const std::vector<glm::dvec3>& queries,
                                                      const MeshView& mesh, const std::string& where) {
    SurfaceCallOptions call;
    call.perPointDistances = true;
    Result<SurfaceResult> kept = engine.hausdorffToSurface(PointView(queries), mesh, call);
    SurfaceOptions options;
    options.backend = Backend::kCpu;
    options.perPointDistances = true;
    Result<SurfaceResult> once = hausdorffToSurface(PointView(queries), mesh, options);
    EXPECT_TRUE(kept && once) << where;
    if (!kept || !once) return std::nullopt;
    EXPECT_EQ(kept->hausdorff, once->hausdorff) << where;
    EXPECT_EQ(kept->directed.queryIndex, once->directed.queryIndex) << where;
    EXPECT_EQ(kept->directed.triangle, once->directed.triangle) << where;
    EXPECT_EQ(kept->directed.surfacePoint, once->directed.surfacePoint) << where;
    EXPECT_EQ(kept->perPoint.distance, once->perPoint.distance) << where;
    EXPECT_EQ(kept->perPoint.triangle, once->perPoint.triangle) << where;
    return *kept;
}

// An Engine of the CPU backend serves surface calls as the free function
// does, per-point distances included, call after call.
TEST(SurfaceApi, AnEngineOfTheCpuBackendEqualsTheFreeFunction) {
    EngineOptions o;
    o.backend = Backend::kCpu;
    Result<Engine> engine = Engine::create(o);
    ASSERT_TRUE(engine) << engine.error().message;
    const Small s;
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        const std::optional<SurfaceResult> kept =
            engineEqualsFreeFunction(*engine, c.queries, MeshView{PointView(c.vertices), c.indices}, c.name);
        ASSERT_TRUE(kept) << c.name;
        EXPECT_EQ(kept->backend, Backend::kCpu) << c.name;
        Result<SurfaceResult> small = engine->hausdorffToSurface(PointView(s.points), s.mesh());
        ASSERT_TRUE(small) << small.error().message;
        EXPECT_EQ(small->hausdorff, 5.0);
    }
}

// An Engine of the CPU backend keeps its last mesh's BVH: the same mesh
// again (the same values from another array, or given in float) reuses it,
// and any change (a vertex moved by one ulp, an index, a vertex more)
// builds a new one; every answer is the free function's (==).
TEST(SurfaceApi, AnEngineOfTheCpuBackendKeepsItsTreeForTheSameMeshOnly) {
    EngineOptions o;
    o.backend = Backend::kCpu;
    Result<Engine> engine = Engine::create(o);
    ASSERT_TRUE(engine) << engine.error().message;
    const std::vector<test::SurfaceCase> cases = test::makeSurfaceCases();
    const auto withQueries = std::find_if(cases.begin(), cases.end(), [](const test::SurfaceCase& c) {
        return !c.queries.empty() && c.indices.size() >= 6;
    });
    ASSERT_NE(withQueries, cases.end());
    const test::SurfaceCase& c = *withQueries;
    const auto call = [&](const MeshView& mesh, uint32_t wantReused, const char* step) {
        const std::optional<SurfaceResult> kept =
            engineEqualsFreeFunction(*engine, c.queries, mesh, c.name + ": " + step);
        ASSERT_TRUE(kept) << c.name << ": " << step;
        EXPECT_EQ(kept->directed.counters.tailTreeReused, wantReused) << c.name << ": " << step;
    };
    std::vector<glm::dvec3> vertices = c.vertices;
    std::vector<uint32_t> indices = c.indices;
    call(MeshView{PointView(vertices), indices}, 0, "first");
    call(MeshView{PointView(vertices), indices}, 1, "same arrays");
    const std::vector<glm::dvec3> copy = vertices;
    const std::vector<uint32_t> copyIndices = indices;
    call(MeshView{PointView(copy), copyIndices}, 1, "same values, other arrays");
    vertices[1].x = std::nextafter(vertices[1].x, 1e300);
    call(MeshView{PointView(vertices), indices}, 0, "a vertex one ulp away");
    call(MeshView{PointView(vertices), indices}, 1, "that mesh again");
    std::swap(indices[0], indices[1]);
    call(MeshView{PointView(vertices), indices}, 0, "two indices swapped");
    vertices.push_back(vertices.back());
    call(MeshView{PointView(vertices), indices}, 0, "a vertex more");
    std::vector<glm::vec3> floats;
    for (const glm::dvec3& v : copy) floats.emplace_back(v);
    std::vector<glm::dvec3> fromFloats(floats.begin(), floats.end());
    call(MeshView{PointView(fromFloats), copyIndices}, 0, "rounded to float, in double");
    call(MeshView{PointView(floats), copyIndices}, 1, "the same values in float");
}

TEST(SurfaceApi, FloatStridedInputsMatchTheBruteForce) {
    const test::SurfaceCase c = test::heightField(3415, 12, 6.0);
    // Interleaved float vertices (position + a colour) and float queries.
    std::vector<float> interleaved;
    std::vector<glm::dvec3> vertices;
    for (const glm::dvec3& v : c.vertices) {
        interleaved.insert(interleaved.end(), {float(v.x), float(v.y), float(v.z), 0.5f, 0.25f, 1.0f});
        vertices.emplace_back(float(v.x), float(v.y), float(v.z));
    }
    std::vector<glm::vec3> queries;
    std::vector<glm::dvec3> queriesD;
    for (int i = 0; i < 300; ++i) {
        const glm::vec3 q(float(i % 17) * 0.4f - 0.5f, float(i % 13) * 0.5f - 0.3f, float(i % 7) - 3.0f);
        queries.push_back(q);
        queriesD.emplace_back(q);
    }
    const MeshView mesh{PointView::floats(interleaved.data(), vertices.size(), 6 * sizeof(float)), c.indices};
    SurfaceOptions options;
    options.perPointDistances = true;
    Result<SurfaceResult> r = hausdorffToSurface(PointView(queries), mesh, options);
    ASSERT_TRUE(r) << r.error().message;
    const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(queriesD, vertices, c.indices);
    EXPECT_EQ(r->hausdorff, want.distance);
    EXPECT_EQ(r->directed.triangle, want.nearest.triangle);
    EXPECT_EQ(r->directed.surfacePoint, want.nearest.point);
    for (size_t i = 0; i < queries.size(); ++i) {
        ASSERT_EQ(r->perPoint.distance[i], std::sqrt(want.perQuery[i].distance2));
        ASSERT_EQ(r->perPoint.triangle[i], want.perQuery[i].triangle);
        ASSERT_EQ(r->perPoint.closest[i], want.perQuery[i].point);
        ASSERT_EQ(r->perPoint.barycentric[i], want.perQuery[i].barycentric);
    }
}

// The per-point arrays of the public call on every surface case (random
// soups, slivers, zero-area and duplicate triangles, far-apart and
// georeferenced placements, points on the surface): each point's distance,
// triangle, closest point and barycentric coordinates equal (==) the double
// brute force over every triangle; independently of the rule, the closest
// point is its barycentric combination of the triangle's vertices (within
// rounding at the case's magnitude), the coordinates are a convex
// combination, the distance is |point - closest|, and the witness is the
// arrays' entry at its query.
TEST(SurfaceApi, PerPointArraysMatchTheBruteForceOnEveryCase) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        SCOPED_TRACE(c.name + ", seed " + std::to_string(c.seed));
        SurfaceOptions options;
        options.perPointDistances = true;
        options.threads = 2;
        Result<SurfaceResult> r =
            hausdorffToSurface(PointView(c.queries), MeshView{PointView(c.vertices), c.indices}, options);
        ASSERT_TRUE(r) << r.error().message;
        const SurfacePerPoint& p = r->perPoint;
        ASSERT_EQ(p.distance.size(), c.queries.size());
        ASSERT_EQ(p.triangle.size(), c.queries.size());
        ASSERT_EQ(p.closest.size(), c.queries.size());
        ASSERT_EQ(p.barycentric.size(), c.queries.size());
        const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
        double magnitude = 0.0;
        for (const glm::dvec3& v : c.vertices)
            magnitude = std::max({magnitude, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
        size_t wrong = 0;
        for (size_t i = 0; i < c.queries.size(); ++i) {
            const oracle::SurfaceNearest& n = want.perQuery[i];
            const bool same = p.distance[i] == std::sqrt(n.distance2) && p.triangle[i] == n.triangle &&
                              p.closest[i] == n.point && p.barycentric[i] == n.barycentric;
            const glm::dvec3& b = p.barycentric[i];
            const uint32_t t = p.triangle[i];
            const glm::dvec3 combination = b.x * c.vertices[c.indices[3 * t]] +
                                           b.y * c.vertices[c.indices[3 * t + 1]] +
                                           b.z * c.vertices[c.indices[3 * t + 2]];
            const glm::dvec3 off = glm::abs(combination - p.closest[i]);
            const bool convex =
                b.x >= 0.0 && b.y >= 0.0 && b.z >= 0.0 && std::abs(b.x + b.y + b.z - 1.0) <= 1e-12;
            const bool onTriangle = std::max({off.x, off.y, off.z}) <= 1e-12 * std::max(magnitude, 1.0);
            const glm::dvec3 d = c.queries[i] - p.closest[i];
            const bool measured = std::abs(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) - p.distance[i]) <=
                                  1e-12 * std::max(p.distance[i], 1.0);
            if (!(same && convex && onTriangle && measured) && ++wrong <= 3)
                ADD_FAILURE() << "point " << i << ": same " << same << ", convex " << convex
                              << ", on triangle " << onTriangle << ", measured " << measured;
        }
        EXPECT_EQ(wrong, 0u);
        const SurfaceDirected& d = r->directed;
        EXPECT_EQ(p.distance[d.queryIndex], d.distance);
        EXPECT_EQ(p.triangle[d.queryIndex], d.triangle);
        EXPECT_EQ(p.closest[d.queryIndex], d.surfacePoint);
        EXPECT_EQ(p.barycentric[d.queryIndex], d.barycentric);
        EXPECT_EQ(*std::max_element(p.distance.begin(), p.distance.end()), r->hausdorff);
    }
}

// perPointDistancesOnly: the same distances and triangles, no closest
// points or barycentric coordinates.
TEST(SurfaceApi, PerPointDistancesOnlyKeepTheDistancesAndTriangles) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        SCOPED_TRACE(c.name);
        SurfaceOptions options;
        options.perPointDistances = true;
        const MeshView mesh{PointView(c.vertices), c.indices};
        const Result<SurfaceResult> all = hausdorffToSurface(PointView(c.queries), mesh, options);
        options.perPointDistancesOnly = true;
        const Result<SurfaceResult> some = hausdorffToSurface(PointView(c.queries), mesh, options);
        ASSERT_TRUE(all && some);
        EXPECT_EQ(some->perPoint.distance, all->perPoint.distance);
        EXPECT_EQ(some->perPoint.triangle, all->perPoint.triangle);
        EXPECT_TRUE(some->perPoint.closest.empty());
        EXPECT_TRUE(some->perPoint.barycentric.empty());
        EXPECT_EQ(some->directed.surfacePoint, all->directed.surfacePoint);
    }
}

// Engine::recycle(SurfaceResult&&): the next per-point call writes into the
// recycled arrays (the same blocks where they are large enough), with the
// one-shot call's entries; a distances-only call after a full one leaves no
// stale closest points.
TEST(SurfaceApi, ARecycledResultsArraysServeTheNextPerPointCall) {
    EngineOptions o;
    o.backend = Backend::kCpu;
    Result<Engine> engine = Engine::create(o);
    ASSERT_TRUE(engine) << engine.error().message;
    std::vector<test::SurfaceCase> cases;
    for (const test::SurfaceCase& c : test::makeSurfaceCases())
        if (c.queries.size() > 8) cases.push_back(c);
    ASSERT_GE(cases.size(), 2u);
    SurfaceCallOptions call;
    call.perPointDistances = true;
    const test::SurfaceCase& big = cases[0].queries.size() >= cases[1].queries.size() ? cases[0] : cases[1];
    const test::SurfaceCase& small = &big == &cases[0] ? cases[1] : cases[0];
    const MeshView bigMesh{PointView(big.vertices), big.indices},
        smallMesh{PointView(small.vertices), small.indices};
    Result<SurfaceResult> first = engine->hausdorffToSurface(PointView(big.queries), bigMesh, call);
    ASSERT_TRUE(first) << first.error().message;
    const double* distances = first->perPoint.distance.data();
    const glm::dvec3* closest = first->perPoint.closest.data();
    engine->recycle(std::move(*first));
    Result<SurfaceResult> second = engine->hausdorffToSurface(PointView(small.queries), smallMesh, call);
    ASSERT_TRUE(second) << second.error().message;
    EXPECT_EQ(second->perPoint.distance.data(), distances);
    EXPECT_EQ(second->perPoint.closest.data(), closest);
    SurfaceOptions oneShot;
    oneShot.backend = Backend::kCpu;
    oneShot.perPointDistances = true;
    const Result<SurfaceResult> want = hausdorffToSurface(PointView(small.queries), smallMesh, oneShot);
    ASSERT_TRUE(want) << want.error().message;
    EXPECT_EQ(second->perPoint.distance, want->perPoint.distance);
    EXPECT_EQ(second->perPoint.triangle, want->perPoint.triangle);
    EXPECT_EQ(second->perPoint.closest, want->perPoint.closest);
    EXPECT_EQ(second->perPoint.barycentric, want->perPoint.barycentric);
    engine->recycle(std::move(*second));
    call.perPointDistancesOnly = true;
    const Result<SurfaceResult> third = engine->hausdorffToSurface(PointView(big.queries), bigMesh, call);
    ASSERT_TRUE(third) << third.error().message;
    EXPECT_EQ(third->perPoint.distance.size(), big.queries.size());
    EXPECT_TRUE(third->perPoint.closest.empty());
    EXPECT_TRUE(third->perPoint.barycentric.empty());
}

TEST(SurfaceApi, IndexOutOfRangeNamesTheTriangle) {
    Small s;
    s.indices[4] = 9;
    Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(r.error().message, "surface B: triangle 1: vertex index 9 out of range (4 vertices)");
}

// The index check runs in chunks on the worker pool: the error names the
// first bad triangle however many chunks hold one and however many threads.
TEST(SurfaceApi, TheFirstIndexOutOfRangeIsNamedOnAnyThreadCount) {
    Small s;
    while (s.indices.size() < 3 * 50000) s.indices.insert(s.indices.end(), {0, 1, 2});  // 150,000 indices
    s.indices[3 * 45000 + 2] = 7;
    s.indices[3 * 30000 + 1] = 5;
    s.indices[3 * 40000] = 6;
    for (const int threads : {1, 2, 5}) {
        SurfaceOptions options;
        options.threads = threads;
        Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh(), options);
        ASSERT_FALSE(r) << threads << " threads";
        EXPECT_EQ(r.error().message, "surface B: triangle 30000: vertex index 5 out of range (4 vertices)")
            << threads << " threads";
    }
}

// An Engine's kept mesh spares the next call with the same mesh its checks
// (api/surface.cpp); any other mesh is checked whole, and a call that fails
// its checks keeps nothing: the kept mesh is still the one kept.
TEST(SurfaceApi, AnEngineChecksEveryMeshButTheOneItKeeps) {
    EngineOptions o;
    o.backend = Backend::kCpu;
    Result<Engine> engine = Engine::create(o);
    ASSERT_TRUE(engine) << engine.error().message;
    Small s;
    Result<SurfaceResult> first = engine->hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_TRUE(first) << first.error().message;
    EXPECT_EQ(first->directed.counters.tailTreeReused, 0u);

    Small bad = s;
    bad.indices[4] = 9;
    Result<SurfaceResult> r = engine->hausdorffToSurface(PointView(bad.points), bad.mesh());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "surface B: triangle 1: vertex index 9 out of range (4 vertices)");
    Small infinite = s;
    infinite.vertices[3].z = std::numeric_limits<double>::infinity();
    r = engine->hausdorffToSurface(PointView(infinite.points), infinite.mesh());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);

    std::vector<glm::dvec3> nan = s.points;
    nan[1].y = std::numeric_limits<double>::quiet_NaN();
    r = engine->hausdorffToSurface(PointView(nan), s.mesh());  // the kept mesh, bad points
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("A"), std::string::npos) << r.error().message;

    Result<SurfaceResult> again = engine->hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_TRUE(again) << again.error().message;
    EXPECT_EQ(again->directed.counters.tailTreeReused, 1u);
    EXPECT_EQ(again->hausdorff, first->hausdorff);
    EXPECT_EQ(again->directed.queryIndex, first->directed.queryIndex);
}

TEST(SurfaceApi, IndicesNotInTriplesAreRefused) {
    Small s;
    s.indices.pop_back();
    Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("not a whole number of triangles"), std::string::npos);
}

TEST(SurfaceApi, NoTrianglesIsRefused) {
    Small s;
    s.indices.clear();
    Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("no triangles"), std::string::npos);
}

TEST(SurfaceApi, EmptyPointsAreRefused) {
    const Small s;
    Result<SurfaceResult> r = hausdorffToSurface(PointView(std::vector<glm::dvec3>{}), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("point set A is empty"), std::string::npos) << r.error().message;
}

TEST(SurfaceApi, NanVertexNamesTheVertex) {
    Small s;
    s.vertices[3].y = std::numeric_limits<double>::quiet_NaN();
    Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("point set B: point 3"), std::string::npos) << r.error().message;
}

TEST(SurfaceApi, MagnitudePastTheLimitIsRefused) {
    Small s;
    s.points[1].x = 1e80;
    Result<SurfaceResult> r = hausdorffToSurface(PointView(s.points), s.mesh());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("2^250"), std::string::npos) << r.error().message;
}

TEST(SurfaceApi, NegativeThreadsAreRefused) {
    const Small s;
    SurfaceOptions options;
    options.threads = -1;
    EXPECT_FALSE(hausdorffToSurface(PointView(s.points), s.mesh(), options));
}

}  // namespace
}  // namespace rthdist
