// Surface to surface (rthdist/surface.hpp, surfaceHausdorff; design.md §12)
// on the CPU backend: pairs whose H is known in closed form (a triangle and
// its parallel offset copy, a convex sphere mesh and its copy scaled by 2, a
// square split along either diagonal, an acute triangle against its corners
// alone, a segment above a triangle), the bounds always bracketing the known
// value with a width within the tolerance; random height fields against an
// independent check by dense exact sampling (every sampled distance at most
// the upper bound, the lower bound at most the sampling's own Lipschitz
// upper bound); determinism over thread counts; every refusal an Error.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <vector>

#include "common/surface_pair_cases.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {
namespace {

using Mesh = test::PairMesh;
using test::expectBrackets;
using test::fromCase;
using test::icosphere;
using test::scaled;
using test::translated;

Result<SurfaceBoundsResult> bounds(const Mesh& a, const Mesh& b, double tolerance, bool directed = false) {
    SurfaceBoundsOptions options;
    options.tolerance = tolerance;
    options.directedOnly = directed;
    return surfaceHausdorff(a.view(), b.view(), options);
}

TEST(SurfaceBounds, TriangleAndItsParallelOffsetCopy) {
    const Mesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    const Mesh b = translated(a, {0, 0, 0.25});
    for (double tolerance : {1e-3, 1e-9}) {
        Result<SurfaceBoundsResult> r = bounds(a, b, tolerance);
        ASSERT_TRUE(r) << r.error().message;
        expectBrackets(*r, 0.25);
        EXPECT_EQ(r->aToB.distance, 0.25);
        EXPECT_EQ(r->bToA.distance, 0.25);
        // The convexity bound settles the whole triangle at once: no split.
        EXPECT_EQ(r->aToB.counters.splits, 0u);
    }
}

TEST(SurfaceBounds, ConvexSphereAndItsCopyScaledByTwo) {
    // B = 2 A, A convex with vertices v on the unit sphere: the nearest point
    // of A to 2v is v (2v - v lies in A's normal cone at v), so h(B, A) =
    // max |v| = 1 (up to the vertices' rounding), and every point x of A has
    // 2x on B: h(A, B) <= max |x| <= 1. H = 1.
    const Mesh a = icosphere(2);
    const Mesh b = scaled(a, 2.0);
    Result<SurfaceBoundsResult> r = bounds(a, b, 1e-6);
    ASSERT_TRUE(r) << r.error().message;
    expectBrackets(*r, 1.0, 1e-15);
    EXPECT_GE(r->bToA.lower, r->aToB.lower);  // the farthest points are B's vertices
}

TEST(SurfaceBounds, SquareSplitAlongEitherDiagonalIsZero) {
    const Mesh a{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3}};
    const Mesh b{a.vertices, {0, 1, 3, 1, 2, 3}};
    for (double tolerance : {1e-3, 1e-5}) {
        Result<SurfaceBoundsResult> r = bounds(a, b, tolerance);
        ASSERT_TRUE(r) << r.error().message;
        expectBrackets(*r, 0.0);
        EXPECT_EQ(r->lower, 0.0);
    }
}

TEST(SurfaceBounds, AcuteTriangleAgainstItsCornersHasItsCircumradius) {
    // B is three zero-area triangles, one per corner of A: the farthest point
    // of A from its corners is the circumcentre (2, 1, 0) (acute triangle),
    // at sqrt(5): an interior maximum the refinement must close in on.
    const Mesh a{{{0, 0, 0}, {4, 0, 0}, {1, 3, 0}}, {0, 1, 2}};
    const Mesh b{a.vertices, {0, 0, 0, 1, 1, 1, 2, 2, 2}};
    Result<SurfaceBoundsResult> r = bounds(a, b, 1e-6 * std::sqrt(25.0 + 9.0));
    ASSERT_TRUE(r) << r.error().message;
    expectBrackets(*r, std::sqrt(5.0), 1e-15);
    EXPECT_EQ(r->bToA.lower, 0.0);
    EXPECT_LE(glm::distance(r->aToB.fromPoint, glm::dvec3(2, 1, 0)), 1e-4);
    EXPECT_EQ(r->aToB.fromTriangle, 0u);
}

TEST(SurfaceBounds, SegmentAboveATriangle) {
    // A: a zero-area triangle, the segment (0,0,1)-(1,0,1). B: the triangle
    // (0,0,0), (1,0,0), (0,1,0). h(A, B) = 1; B's farthest point from the
    // segment is (0,1,0), at sqrt(2).
    const Mesh a{{{0, 0, 1}, {1, 0, 1}}, {0, 1, 1}};
    const Mesh b{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = bounds(a, b, 1e-8);
    ASSERT_TRUE(r) << r.error().message;
    expectBrackets(*r, std::sqrt(2.0), 1e-15);
    EXPECT_EQ(r->bToA.fromPoint, glm::dvec3(0, 1, 0));
    EXPECT_LE(r->aToB.lower, 1.0);
    EXPECT_GE(r->aToB.upper, 1.0);
}

TEST(SurfaceBounds, DirectedOnlyHoldsItsOwnWidth) {
    const Mesh a{{{0, 0, 1}, {1, 0, 1}}, {0, 1, 1}};
    const Mesh b{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = bounds(a, b, 1e-8, true);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_TRUE(r->directed);
    expectBrackets(*r, 1.0, 1e-15);
    EXPECT_EQ(r->bToA.counters.queries, 0u);
}

TEST(SurfaceBounds, HeightFieldsAgainstDenseSampling) {
    for (uint64_t seed : {3470u, 3471u, 3472u}) {
        const auto [a, b] = test::heightFieldPair(seed);
        std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
        Result<SurfaceBoundsResult> r = bounds(a, b, 1e-5);
        ASSERT_TRUE(r) << r.error().message;
        test::expectSampledBothWays(a, b, *r, 1e-5);
    }
}

TEST(SurfaceBounds, SameResultOnEveryThreadCount) {
    const Mesh a = fromCase(test::heightField(3473, 6, 4.0));
    const Mesh b = translated(fromCase(test::heightField(3474, 5, 4.0)), {0.1, 0.2, 0.3});
    SurfaceBoundsOptions options;
    options.tolerance = 1e-6;
    options.threads = 1;
    Result<SurfaceBoundsResult> one = surfaceHausdorff(a.view(), b.view(), options);
    options.threads = 3;
    Result<SurfaceBoundsResult> three = surfaceHausdorff(a.view(), b.view(), options);
    ASSERT_TRUE(one && three);
    EXPECT_EQ(one->lower, three->lower);
    EXPECT_EQ(one->upper, three->upper);
    EXPECT_EQ(one->aToB.fromPoint, three->aToB.fromPoint);
    EXPECT_EQ(one->bToA.toPoint, three->bToA.toPoint);
    EXPECT_EQ(one->aToB.counters.queries, three->aToB.counters.queries);
}

TEST(SurfaceBounds, FarFromTheOriginKeepsItsPrecision) {
    // Georeferenced: the slack scales with the meshes' extent (the work
    // frame is centred on their box), so 1e-6 of the diagonal is reachable.
    const glm::dvec3 utm(500000.0, 5400000.0, 300.0);
    const Mesh a = translated(Mesh{{{0, 0, 0}, {10, 0, 0}, {0, 10, 0}}, {0, 1, 2}}, utm);
    const Mesh b = translated(a, {0, 0, 0.5});
    Result<SurfaceBoundsResult> r = bounds(a, b, 1e-5);
    ASSERT_TRUE(r) << r.error().message;
    expectBrackets(*r, 0.5, 1e-9);  // the translation by 0.5 rounds at 5.4e6
    EXPECT_LT(r->slack, 1e-10);
}

TEST(SurfaceBounds, DefaultToleranceIsATenThousandthOfTheDiagonal) {
    const Mesh a{{{0, 0, 0}, {3, 0, 0}, {0, 4, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = bounds(a, translated(a, {0, 0, 12}), 0.0);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_DOUBLE_EQ(r->tolerance, 1e-4 * 13.0);
    expectBrackets(*r, 12.0);
}

TEST(SurfaceBounds, RefusalsAreErrors) {
    const Mesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    const Mesh bad{a.vertices, {0, 1, 7}};
    const Mesh none{a.vertices, {}};
    Result<SurfaceBoundsResult> r = bounds(a, bad, 1e-3);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("surface B: triangle 0: vertex index 7"), std::string::npos)
        << r.error().message;
    r = bounds(none, a, 1e-3);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("surface A has no triangles"), std::string::npos) << r.error().message;
    for (double t : {-1.0, std::nan(""), std::numeric_limits<double>::infinity(), 1e-20}) {
        r = bounds(a, a, t);
        ASSERT_FALSE(r) << t;
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(r.error().message.find("tolerance"), std::string::npos) << r.error().message;
    }
}

TEST(SurfaceBounds, QueryLimitIsOutOfMemoryWithTheBoundsReached) {
    const Mesh a{{{0, 0, 0}, {4, 0, 0}, {1, 3, 0}}, {0, 1, 2}};
    const Mesh b{a.vertices, {0, 0, 0, 1, 1, 1, 2, 2, 2}};
    SurfaceBoundsOptions options;
    options.tolerance = 1e-9;
    options.maxQueries = 50;
    Result<SurfaceBoundsResult> r = surfaceHausdorff(a.view(), b.view(), options);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kOutOfMemory);
    EXPECT_NE(r.error().message.find("maxQueries"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("bounds reached"), std::string::npos) << r.error().message;
}

TEST(SurfaceBounds, CancelIsAnError) {
    const Mesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    std::atomic<bool> cancel{true};
    SurfaceBoundsOptions options;
    options.cancel = &cancel;
    Result<SurfaceBoundsResult> r = surfaceHausdorff(a.view(), translated(a, {0, 0, 1}).view(), options);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kCancelled);
}

}  // namespace
}  // namespace rthdist
