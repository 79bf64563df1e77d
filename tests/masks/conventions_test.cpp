// The conventions table (include/rthdist/mask_conventions.hpp): every row is
// reachable by its name, its texts and rules are what the library reports,
// and a row's rules alone decide its numbers (two rows with the same rules
// but the empty texts give the same values).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "masks_test_support.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

// Two boxes of a 12 x 10 x 8 grid, B shifted and one voxel longer, at an
// anisotropic spacing.
std::array<Volume, 2> boxPair() {
    std::array<Volume, 2> out;
    for (int k = 0; k < 2; ++k) {
        Volume& v = out[size_t(k)];
        v.path = k == 0 ? "a" : "b";
        v.dims = {12, 10, 8};
        v.voxelToWorld = glm::dmat4(1.0);
        v.voxelToWorld[0][0] = 0.8;
        v.voxelToWorld[1][1] = 1.1;
        v.voxelToWorld[2][2] = 2.5;
        v.labels8.assign(size_t(v.voxelCount()), 0);
        for (int64_t z = 2; z < 6; ++z)
            for (int64_t y = 2 + k; y < 7 + k; ++y)
                for (int64_t x = 3; x < 8 + 2 * k; ++x) v.labels8[size_t(x + 12 * (y + 10 * z))] = 1;
    }
    return out;
}

TEST(MaskConventions, EveryRowByItsName) {
    std::set<std::string> names;
    for (size_t i = 0; i < kAllConventions.size(); ++i) {
        const Convention c = kAllConventions[i];
        const ConventionRules& row = conventionRules(c);
        EXPECT_EQ(size_t(c), i);
        EXPECT_EQ(row.convention, c);
        EXPECT_TRUE(names.insert(row.name).second) << row.name << " twice";
        Convention parsed{};
        ASSERT_TRUE(parseConvention(row.name, parsed)) << row.name;
        EXPECT_EQ(parsed, c);
        EXPECT_STREQ(conventionName(c), row.name);
        EXPECT_STREQ(conventionRule(c), row.rule);
        EXPECT_NE(conventionNames().find(row.name), std::string::npos);
    }
    Convention none{};
    EXPECT_FALSE(parseConvention("no-such-tool", none));
    EXPECT_STREQ(conventionName(Convention(kAllConventions.size())), "?");
}

TEST(MaskConventions, EmptyTextsAreTheRows) {
    for (Convention c : kAllConventions) {
        const ConventionRules& row = conventionRules(c);
        const EmptyValues both = emptyValues(c, EmptyStatus::kBothEmpty, {0.0, 95.0});
        EXPECT_EQ(both.hd, row.bothEmpty.hd) << row.name;
        EXPECT_EQ(both.surfaceDice, row.bothEmpty.surfaceDice) << row.name;
        ASSERT_EQ(both.hdPercentile.size(), 2u);
        EXPECT_EQ(both.hdPercentile[0], row.bothEmpty.hdPercentileAt0) << row.name;
        EXPECT_EQ(both.hdPercentile[1], row.bothEmpty.hdPercentile) << row.name;
        const EmptyValues a = emptyValues(c, EmptyStatus::kAEmpty, {95.0});
        EXPECT_EQ(a.aToB.mean, row.oneEmpty.emptySide.mean) << row.name;
        EXPECT_EQ(a.bToA.mean, row.oneEmpty.otherSide.mean) << row.name;
        const EmptyValues b = emptyValues(c, EmptyStatus::kBEmpty, {95.0});
        EXPECT_EQ(b.bToA.surfaceOverlap, row.oneEmpty.emptySide.overlap) << row.name;
        EXPECT_EQ(b.aToB.surfaceOverlap, row.oneEmpty.otherSide.overlap) << row.name;
    }
}

// Each row's rules reach the result: its connectivity, point set (through
// the point counts), surface measures and HD-p.
TEST(MaskConventions, RulesReachTheResult) {
    const auto [a, b] = boxPair();
    Options o;
    o.backend = Backend::kCpu;
    auto engine = makeMaskEngine(o);
    ASSERT_TRUE(engine) << engine.error().message;
    for (Convention c : kAllConventions) {
        const ConventionRules& row = conventionRules(c);
        MaskOptions mo;
        mo.convention = c;
        mo.connectivity = 26;
        mo.percentiles = {50.0, 95.0};
        auto r = compareMasks(*engine, a, {}, b, {}, mo);
        ASSERT_TRUE(r) << row.name << ": " << r.error().message;
        EXPECT_EQ(r->convention, c);
        EXPECT_EQ(r->connectivity, row.points != PointSet::kBoundary ? 0
                                   : row.connectivityOption          ? 26
                                                                     : 6)
            << row.name;
        EXPECT_EQ(std::isnan(r->surfaceDice), !row.surfaceMeasures) << row.name;
        EXPECT_EQ(r->hdPercentile.size(), row.percentile == DirectedPercentile::kNone ? 0u : 2u) << row.name;
        EXPECT_GT(r->hd, 0.0) << row.name;
        if (row.points == PointSet::kForeground) EXPECT_EQ(r->aToB.points, 5u * 5u * 4u) << row.name;
    }
}

}  // namespace
}  // namespace rthdist::masks
