// The queries' visiting order (cpu/query_order.hpp): a permutation of the
// indices in Morton order of their cells, ties by index, the same on any
// thread count; input order (empty) for few queries and for an input
// already in space order. And the surface search's answers do not depend
// on it: samples in random order and the same samples sorted give the same
// value, witness and per-point entries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "common/rng.hpp"
#include "common/surface_cases.hpp"
#include "cpu/query_order.hpp"
#include "cpu/surface_search.hpp"
#include "rthdist_morton.h"

namespace rthdist {
namespace {

std::vector<glm::dvec3> randomPoints(size_t n, uint64_t seed) {
    test::Rng rng(seed);
    std::vector<glm::dvec3> p;
    for (size_t i = 0; i < n; ++i) p.emplace_back(rng.uniform(-3, 5), rng.uniform(0, 1), rng.uniform(10, 12));
    return p;
}

uint32_t keyOf(const glm::dvec3& p, const glm::dvec3& lo, double toCell) {
    const glm::dvec3 c = (p - lo) * toCell;
    auto cell = [](double v) { return uint32_t(std::clamp(v, 0.0, 1023.0)); };
    return shared::mortonEncode(cell(c.x), cell(c.y), cell(c.z));
}

TEST(QueryOrder, RandomPointsAreVisitedInMortonOrderTiesByIndex) {
    const std::vector<glm::dvec3> p = randomPoints(20000, 3486);
    const std::vector<uint32_t> order = cpu::spatialOrder(PointView(p), 2);
    ASSERT_EQ(order.size(), p.size());
    std::vector<uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    std::vector<uint32_t> identity(p.size());
    std::iota(identity.begin(), identity.end(), 0u);
    EXPECT_EQ(sorted, identity);  // a permutation
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::dvec3& v : p) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
    }
    const double toCell = 1023.0 / std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    for (size_t i = 1; i < order.size(); ++i) {
        const uint32_t a = keyOf(p[order[i - 1]], lo, toCell), b = keyOf(p[order[i]], lo, toCell);
        ASSERT_TRUE(a < b || (a == b && order[i - 1] < order[i])) << i;
    }
    for (int threads : {1, 3, 0}) EXPECT_EQ(cpu::spatialOrder(PointView(p), threads), order) << threads;
}

TEST(QueryOrder, FewQueriesAndInputInSpaceOrderKeepTheirOrder) {
    std::vector<glm::dvec3> p = randomPoints(cpu::kSpatialOrderFrom - 1, 3487);
    EXPECT_TRUE(cpu::spatialOrder(PointView(p), 2).empty());
    p = randomPoints(50000, 3488);
    const std::vector<uint32_t> order = cpu::spatialOrder(PointView(p), 2);
    ASSERT_EQ(order.size(), p.size());
    std::vector<glm::dvec3> inOrder;
    for (const uint32_t i : order) inOrder.push_back(p[i]);
    EXPECT_TRUE(cpu::spatialOrder(PointView(inOrder), 2).empty());
}

TEST(QueryOrder, TheSearchGivesTheSameAnswersInAnyInputOrder) {
    test::SurfaceCase c = test::heightField(3489, 30, 8.0);
    const std::vector<glm::dvec3> p = randomPoints(30000, 3489);
    const std::vector<uint32_t> order = cpu::spatialOrder(PointView(p), 2);
    ASSERT_FALSE(order.empty());
    std::vector<glm::dvec3> inOrder;
    for (const uint32_t i : order) inOrder.push_back(p[i]);
    SurfaceOptions options;
    options.backend = Backend::kCpu;
    options.threads = 2;
    options.perPointDistances = true;
    const MeshView mesh{PointView(c.vertices), c.indices};
    const Result<SurfaceResult> a = cpu::surfaceSearch(PointView(p), mesh, 20.0, options);
    const Result<SurfaceResult> b = cpu::surfaceSearch(PointView(inOrder), mesh, 20.0, options);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->hausdorff, b->hausdorff);
    EXPECT_EQ(a->directed.queryPoint, b->directed.queryPoint);
    EXPECT_EQ(a->directed.triangle, b->directed.triangle);
    for (size_t k = 0; k < order.size(); ++k) {
        ASSERT_EQ(a->perPoint.distance[order[k]], b->perPoint.distance[k]) << k;
        ASSERT_EQ(a->perPoint.triangle[order[k]], b->perPoint.triangle[k]) << k;
    }
}

}  // namespace
}  // namespace rthdist
