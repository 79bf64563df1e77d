// Surface to surface on the GPU backend named by RTHDIST_TEST_BACKEND
// (src/api/surface_pair_gpu.hpp; design.md §12, "On a GPU backend"), with
// the validation layer (any message fails): the closed-form pairs of the
// CPU backend's suite (tests/api/surface_bounds_test.cpp) at tolerances
// above the GPU floor, the bounds bracketing the known H and meeting the
// CPU backend's; height fields against dense exact sampling; a georeferenced
// pair; the same bounds call after call; the floor refused with its value,
// and a tolerance just above it reached.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/surface_pair_cases.hpp"
#include "gpu_algo/gpu_test_support.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {
namespace {

using test::expectBrackets;
using test::PairMesh;
using test::translated;

SurfaceBoundsOptions gpuPairOptions(double tolerance, bool directed = false) {
    SurfaceBoundsOptions o;
    o.backend = test::backendUnderTest();
    o.validation = true;
    o.tolerance = tolerance;
    o.directedOnly = directed;
    return o;
}

// The GPU backend's bounds, checked against the CPU backend's on the same
// pair: both certified, so they meet (max lower <= min upper).
Result<SurfaceBoundsResult> onGpu(const PairMesh& a, const PairMesh& b, double tolerance,
                                  bool directed = false) {
    Result<SurfaceBoundsResult> gpu =
        surfaceHausdorff(a.view(), b.view(), gpuPairOptions(tolerance, directed));
    if (!gpu) return gpu;
    EXPECT_EQ(gpu->backend, test::backendUnderTest());
    EXPECT_EQ(gpu->validationMessages, 0u);
    SurfaceBoundsOptions cpuOptions;
    cpuOptions.backend = Backend::kCpu;
    cpuOptions.tolerance = tolerance;
    cpuOptions.directedOnly = directed;
    Result<SurfaceBoundsResult> cpu = surfaceHausdorff(a.view(), b.view(), cpuOptions);
    EXPECT_TRUE(cpu) << cpu.error().message;
    if (cpu) {
        EXPECT_LE(std::max(gpu->lower, cpu->lower), std::min(gpu->upper, cpu->upper))
            << "gpu [" << gpu->lower << ", " << gpu->upper << "] cpu [" << cpu->lower << ", " << cpu->upper
            << "]";
    }
    return gpu;
}

#define RTHDIST_REQUIRE_GPU_PAIR(r)                                                            \
    if (!(r) && (r).error().code == ErrorCode::kNoDevice) GTEST_SKIP() << (r).error().message; \
    ASSERT_TRUE(r) << (r).error().message

TEST(SurfacePairGpu, TriangleAndItsParallelOffsetCopy) {
    const PairMesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = onGpu(a, translated(a, {0, 0, 0.25}), 1e-3);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, 0.25);
    EXPECT_EQ(r->aToB.distance, 0.25);
    EXPECT_EQ(r->bToA.distance, 0.25);
}

TEST(SurfacePairGpu, ConvexSphereAndItsCopyScaledByTwo) {
    const PairMesh a = test::icosphere(2);
    Result<SurfaceBoundsResult> r = onGpu(a, test::scaled(a, 2.0), 1e-3);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, 1.0, 1e-15);
}

TEST(SurfacePairGpu, SquareSplitAlongEitherDiagonalIsZero) {
    const PairMesh a{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3}};
    Result<SurfaceBoundsResult> r = onGpu(a, PairMesh{a.vertices, {0, 1, 3, 1, 2, 3}}, 1e-3);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, 0.0);
    EXPECT_EQ(r->lower, 0.0);
}

TEST(SurfacePairGpu, AcuteTriangleAgainstItsCornersHasItsCircumradius) {
    // The farthest point of A from its corners is the circumcentre (2, 1, 0), at sqrt(5).
    const PairMesh a{{{0, 0, 0}, {4, 0, 0}, {1, 3, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = onGpu(a, PairMesh{a.vertices, {0, 0, 0, 1, 1, 1, 2, 2, 2}}, 1e-3);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, std::sqrt(5.0), 1e-15);
    EXPECT_EQ(r->bToA.lower, 0.0);
    EXPECT_LE(glm::distance(r->aToB.fromPoint, glm::dvec3(2, 1, 0)), 0.05);
}

TEST(SurfacePairGpu, SegmentAboveATriangleDirectedAndBoth) {
    const PairMesh a{{{0, 0, 1}, {1, 0, 1}}, {0, 1, 1}};
    const PairMesh b{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
    Result<SurfaceBoundsResult> r = onGpu(a, b, 1e-3);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, std::sqrt(2.0), 1e-15);
    EXPECT_EQ(r->bToA.fromPoint, glm::dvec3(0, 1, 0));
    Result<SurfaceBoundsResult> directed = onGpu(a, b, 1e-3, true);
    ASSERT_TRUE(directed) << directed.error().message;
    EXPECT_TRUE(directed->directed);
    expectBrackets(*directed, 1.0, 1e-15);
    EXPECT_EQ(directed->bToA.counters.queries, 0u);
}

TEST(SurfacePairGpu, HeightFieldsAgainstDenseSampling) {
    for (uint64_t seed : {3470u, 3471u}) {
        const auto [a, b] = test::heightFieldPair(seed);
        Result<SurfaceBoundsResult> r = onGpu(a, b, 1e-3);
        RTHDIST_REQUIRE_GPU_PAIR(r);
        test::expectSampledBothWays(a, b, *r, 1e-3);
    }
}

TEST(SurfacePairGpu, GeoreferencedPairKeepsItsPrecision) {
    const glm::dvec3 utm(500000.0, 5400000.0, 300.0);
    const PairMesh a = translated(PairMesh{{{0, 0, 0}, {10, 0, 0}, {0, 10, 0}}, {0, 1, 2}}, utm);
    Result<SurfaceBoundsResult> r = onGpu(a, translated(a, {0, 0, 0.5}), 1e-2);
    RTHDIST_REQUIRE_GPU_PAIR(r);
    expectBrackets(*r, 0.5, 1e-9);
}

TEST(SurfacePairGpu, TheSameBoundsCallAfterCall) {
    const PairMesh a = test::fromCase(test::heightField(3473, 6, 4.0));
    const PairMesh b = translated(test::fromCase(test::heightField(3474, 5, 4.0)), {0.1, 0.2, 0.3});
    Result<SurfaceBoundsResult> one = surfaceHausdorff(a.view(), b.view(), gpuPairOptions(1e-3));
    RTHDIST_REQUIRE_GPU_PAIR(one);
    Result<SurfaceBoundsResult> two = surfaceHausdorff(a.view(), b.view(), gpuPairOptions(1e-3));
    ASSERT_TRUE(two) << two.error().message;
    EXPECT_EQ(one->lower, two->lower);
    EXPECT_EQ(one->upper, two->upper);
    EXPECT_EQ(one->aToB.fromPoint, two->aToB.fromPoint);
    EXPECT_EQ(one->bToA.toPoint, two->bToA.toPoint);
    EXPECT_EQ(one->aToB.counters.queries, two->aToB.counters.queries);
}

TEST(SurfacePairGpu, TheFloorIsRefusedWithItsValueAndReachedJustAbove) {
    // Box [0, 3] x [0, 3] x [0, 0.25]: around its centre the largest
    // coordinate is 1.5 < 2, so the floor is 2^-14 * 2 = 2^-13.
    const PairMesh a{{{0, 0, 0}, {3, 0, 0}, {0, 3, 0}}, {0, 1, 2}};
    const PairMesh b = translated(a, {0, 0, 0.25});
    Result<SurfaceBoundsResult> below = surfaceHausdorff(a.view(), b.view(), gpuPairOptions(0x1p-13 * 0.999));
    if (!below && below.error().code == ErrorCode::kNoDevice) GTEST_SKIP() << below.error().message;
    ASSERT_FALSE(below);
    EXPECT_EQ(below.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(below.error().message.find("floor 0.0001220703125"), std::string::npos)
        << below.error().message;
    EXPECT_NE(below.error().message.find(backendName(test::backendUnderTest())), std::string::npos);
    Result<SurfaceBoundsResult> at = onGpu(a, b, 0x1p-13);
    ASSERT_TRUE(at) << at.error().message;
    expectBrackets(*at, 0.25);
}

}  // namespace
}  // namespace rthdist
