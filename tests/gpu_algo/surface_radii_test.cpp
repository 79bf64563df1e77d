// The point-to-surface search's radii (src/gpu_algo/surface_search.hpp,
// SurfaceRadii) on the host, no device: the first radius from the
// triangles' sides and the queries' spacing, the one submission's radii
// (first, 4x it, at most the cover radius). The queries they leave open go
// back to the host while few (openQueriesToHost: open x triangles at most
// the host work), else to the tail's tree descent (surface_tree_test.cpp,
// gpu_surface_test.cpp). None decides a value (the host proves it); these
// pin the cost.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "gpu_algo/surface_search.hpp"

namespace rthdist::gpu_algo {
namespace {

TEST(SurfaceRadii, FirstIsHalfTheMeanSideForDenseQueries) {
    // 10^4 queries over an area of 1: spacing 0.01, below the sides.
    const SurfaceRadii r(0.1, 1.0, 10000, 2.0);
    EXPECT_EQ(r.first(), 0.05);
    EXPECT_EQ(r.cover(), 2.0 * (1.0 + 0x1p-10) + 0x1p-24);
}

TEST(SurfaceRadii, FirstIsHalfTheQuerySpacingForSparseQueries) {
    // 100 queries over an area of 4: spacing 0.2, above the sides of 0.01.
    const SurfaceRadii r(0.01, 4.0, 100, 2.0);
    EXPECT_DOUBLE_EQ(r.first(), 0.1);
}

TEST(SurfaceRadii, FirstHasAFloorAndIsAtMostCover) {
    // Everything at one point: no side, no area, no diagonal.
    const SurfaceRadii none(0.0, 0.0, 3, 0.0);
    EXPECT_EQ(none.first(), 0x1p-24);
    EXPECT_EQ(none.cover(), 0x1p-24);
    // One query over a large area: the spacing is past the union's diagonal.
    const SurfaceRadii one(0.01, 100.0, 1, 1.0);
    EXPECT_EQ(one.first(), one.cover());
}

TEST(SurfaceRadii, TheFirstSubmissionHoldsTwoRadii) {
    EXPECT_EQ(SurfaceRadii(0.1, 1.0, 10000, 2.0).start(), (std::vector<double>{0.05, 0.2}));
    const SurfaceRadii near(0.1, 1.0, 10000, 0.1);  // 4x first is past cover: cover second
    EXPECT_EQ(near.start(), (std::vector<double>{0.05, near.cover()}));
    const SurfaceRadii one(0.01, 100.0, 1, 1.0);  // first is cover: one radius
    EXPECT_EQ(one.start(), (std::vector<double>{one.cover()}));
    for (const SurfaceRadii& r : {near, one, SurfaceRadii(0.1, 1.0, 10000, 2.0)})
        EXPECT_LE(r.start().size(), SurfaceRadii::kStartRadii);
}

// The host work: Tuning::surfaceHostWork where set, else 2^19 per host
// thread; open queries go to the host while open x triangles is at most it.
TEST(SurfaceRadii, FewOpenQueriesGoToTheHost) {
    EXPECT_EQ(surfaceHostWork(Tuning{}, 2), 2 * kSurfaceHostWorkPerThread);
    EXPECT_EQ(surfaceHostWork(Tuning{}, 16), 16 * kSurfaceHostWorkPerThread);
    Tuning tuned;
    tuned.surfaceHostWork = 12345;
    EXPECT_EQ(surfaceHostWork(tuned, 16), 12345u);
    tuned.surfaceHostWork = 0;
    EXPECT_EQ(surfaceHostWork(tuned, 16), 0u);
    // The bunny's 69,451 triangles on 2 threads: 15 open queries go back, 16 do not.
    const uint64_t twoThreads = surfaceHostWork(Tuning{}, 2);
    EXPECT_TRUE(openQueriesToHost(8, 69451, twoThreads));
    EXPECT_TRUE(openQueriesToHost(15, 69451, twoThreads));
    EXPECT_FALSE(openQueriesToHost(16, 69451, twoThreads));
    EXPECT_TRUE(openQueriesToHost(15 * 69451, 1, 15 * 69451));  // the bound itself
    EXPECT_FALSE(openQueriesToHost(15 * 69451 + 1, 1, 15 * 69451));
    // None open: nothing to hand back; no host work: always the tree.
    EXPECT_FALSE(openQueriesToHost(0, 69451, twoThreads));
    EXPECT_FALSE(openQueriesToHost(1, 1, 0));
    // Past 64 bits of queries x triangles: the division keeps it exact.
    EXPECT_TRUE(openQueriesToHost(1, uint64_t(1) << 40, UINT64_MAX));
    EXPECT_FALSE(openQueriesToHost(uint64_t(1) << 40, uint64_t(1) << 40, UINT64_MAX));
}

}  // namespace
// Every query down the tree without radii: where Tuning::surfaceDescend
// says so, else for at most kDescendQueries queries, whatever the
// triangles (session 30's rows: bunny>res4's 35,947 queries,
// bunny-res4>bunny's 453, dragon_vrip_res2>res3's 100,250,
// bunny-scans>bunny's 362,272, dragon>res2's 437,645 and 4M samples
// against dragon_vrip_res2's 202,520 triangles).
TEST(SurfaceRadii, UpToKDescendQueriesDescendOnly) {
    const Tuning rule;
    EXPECT_TRUE(descendOnly(rule, 35947));
    EXPECT_TRUE(descendOnly(rule, 453));
    EXPECT_TRUE(descendOnly(rule, 100250));
    EXPECT_TRUE(descendOnly(rule, 362272));
    EXPECT_TRUE(descendOnly(rule, 437645));
    EXPECT_TRUE(descendOnly(rule, 4000000));
    EXPECT_TRUE(descendOnly(rule, kDescendQueries));
    EXPECT_FALSE(descendOnly(rule, kDescendQueries + 1));
    EXPECT_FALSE(descendOnly(rule, uint64_t(10000000)));
    Tuning forced;
    forced.surfaceDescend = true;
    EXPECT_TRUE(descendOnly(forced, kDescendQueries + 1));
    forced.surfaceDescend = false;
    EXPECT_FALSE(descendOnly(forced, 35947));
    EXPECT_FALSE(descendOnly(forced, 1));
}

// The tail's lanes a query on a GPU: one where many descend; more, up to
// 32, while the queries that descend x lanes stay within kTailThreads;
// never past kTailMostThreads dispatched (the call's queries x lanes). A
// CPU device takes one. Forced counts are rounded down to a power of two,
// within the same limits, on either device.
TEST(SurfaceRadii, FewDescendingQueriesShareTheirDescentWithLanes) {
    const Tuning rule;
    const bool gpu = false, cpu = true;
    EXPECT_EQ(tailLaneBits(rule, gpu, 453, 453), 5u);    // bunny-res4 > bunny: 32 lanes
    EXPECT_EQ(tailLaneBits(rule, gpu, 5205, 5205), 5u);  // dragon-res4 > dragon: 32
    EXPECT_EQ(tailLaneBits(rule, gpu, 35947, 35947), 2u);
    EXPECT_EQ(tailLaneBits(rule, gpu, kTailThreads / 4, kTailThreads / 4), 2u);
    EXPECT_EQ(tailLaneBits(rule, gpu, kTailThreads / 4 + 1, kTailThreads / 4 + 1), 1u);
    EXPECT_EQ(tailLaneBits(rule, gpu, kTailThreads, kTailThreads), 0u);
    EXPECT_EQ(tailLaneBits(rule, gpu, 1, 1), kTailMostLaneBits);
    EXPECT_EQ(tailLaneBits(rule, gpu, 0, 10), kTailMostLaneBits);  // (no query open: the dispatch returns)
    // A few open queries of many: the dispatch's threads bound the lanes.
    EXPECT_EQ(tailLaneBits(rule, gpu, 100, kTailMostThreads / 4), 2u);
    EXPECT_EQ(tailLaneBits(rule, gpu, 100, kTailMostThreads), 0u);
    EXPECT_EQ(tailLaneBits(rule, gpu, 100, uint64_t(1) << 32), 0u);
    // A CPU device: one lane unless forced.
    EXPECT_EQ(tailLaneBits(rule, cpu, 453, 453), 0u);
    Tuning forced;
    for (const bool device : {gpu, cpu}) {
        for (const auto& [lanes, bits] :
             {std::pair{0u, 0u}, {1u, 0u}, {2u, 1u}, {3u, 1u}, {8u, 3u}, {31u, 4u}, {32u, 5u}, {1000u, 5u}}) {
            forced.surfaceTailLanes = lanes;
            EXPECT_EQ(tailLaneBits(forced, device, 35947, 35947), bits) << lanes;
        }
        forced.surfaceTailLanes = 32;
        EXPECT_EQ(tailLaneBits(forced, device, 10, kTailMostThreads / 8), 3u);
    }
}

}  // namespace rthdist::gpu_algo
