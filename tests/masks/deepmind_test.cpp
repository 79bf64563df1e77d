// The deepmind convention's parts: the surfel area table (symmetries of the
// cube, complements, shapes whose area is known in closed form), surfel
// extraction against a brute force, NumPy's summation and the area-weighted
// percentile, and compareMasks on two one-voxel masks worked out by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <random>
#include <vector>

#include "masks/area_weighted.hpp"
#include "masks/surfel_area.hpp"
#include "masks/surfels.hpp"
#include "masks_test_support.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

using detail::neighbourBit;
using detail::surfelAreaTable;

const glm::dvec3 kSpacing(0.5, 0.7, 3.0);

// The code whose selected corners are `corners` (offsets along axes 0, 1, 2).
uint8_t codeOf(const std::vector<std::array<int, 3>>& corners) {
    uint8_t code = 0;
    for (const auto& c : corners) code |= neighbourBit(c[0], c[1], c[2]);
    return code;
}

// The code after moving corner offset o to o' with o'[axis] = o[perm[axis]] ^ flip[axis].
uint8_t transformCode(uint8_t code, std::array<int, 3> perm, std::array<int, 3> flip) {
    uint8_t out = 0;
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int c = 0; c < 2; ++c) {
                if (!(code & neighbourBit(a, b, c))) continue;
                const int o[3] = {a, b, c};
                out |= neighbourBit(o[perm[0]] ^ flip[0], o[perm[1]] ^ flip[1], o[perm[2]] ^ flip[2]);
            }
    return out;
}

TEST(DeepmindSurfelArea, OnlyCodes0And255HaveNoArea) {
    const auto area = surfelAreaTable(kSpacing);
    EXPECT_EQ(area[0], 0.0);
    EXPECT_EQ(area[255], 0.0);
    for (int code = 1; code < 255; ++code) EXPECT_GT(area[size_t(code)], 0.0) << "code " << code;
}

TEST(DeepmindSurfelArea, ComplementHasTheSameArea) {
    for (glm::dvec3 s : {glm::dvec3(1.0), kSpacing}) {
        const auto area = surfelAreaTable(s);
        for (int code = 1; code < 255; ++code)
            EXPECT_NEAR(area[size_t(code)], area[size_t(255 - code)], 1e-12) << "code " << code;
    }
}

// Each of the cube's 48 rotations and reflections maps a code to another
// whose area, at the spacing permuted the same way, is the same.
TEST(DeepmindSurfelArea, RotationsAndReflectionsPreserveArea) {
    const auto area = surfelAreaTable(kSpacing);
    std::array<int, 3> perm{0, 1, 2};
    int checked = 0;
    do {
        const glm::dvec3 permuted(kSpacing[perm[0]], kSpacing[perm[1]], kSpacing[perm[2]]);
        const auto moved = surfelAreaTable(permuted);
        for (int f = 0; f < 8; ++f) {
            const std::array<int, 3> flip{f >> 2, (f >> 1) & 1, f & 1};
            for (int code = 0; code < 256; ++code) {
                const uint8_t to = transformCode(uint8_t(code), perm, flip);
                ASSERT_NEAR(area[size_t(code)], moved[to], 1e-12)
                    << "code " << code << " -> " << int(to) << " perm " << perm[0] << perm[1] << perm[2];
                ++checked;
            }
        }
    } while (std::next_permutation(perm.begin(), perm.end()));
    EXPECT_EQ(checked, 48 * 256);
}

// Four corners on one face of the dual cube: a flat piece of a large
// object's face, exactly one voxel face (the product of the two spacings).
TEST(DeepmindSurfelArea, FlatFaceIsTheVoxelFace) {
    const auto area = surfelAreaTable(kSpacing);
    const double faceArea[3] = {kSpacing.y * kSpacing.z, kSpacing.x * kSpacing.z, kSpacing.x * kSpacing.y};
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            std::vector<std::array<int, 3>> face;
            for (int u = 0; u < 2; ++u)
                for (int v = 0; v < 2; ++v) {
                    std::array<int, 3> c{};
                    c[size_t(axis)] = side;
                    c[size_t((axis + 1) % 3)] = u;
                    c[size_t((axis + 2) % 3)] = v;
                    face.push_back(c);
                }
            EXPECT_EQ(area[codeOf(face)], faceArea[axis]) << "axis " << axis << " side " << side;
        }
}

// One corner: the triangle through the midpoints of its three edges; one
// edge (two corners along axis 0): the rectangle of length s.x across it.
TEST(DeepmindSurfelArea, CornerAndEdgePiecesInClosedForm) {
    const auto area = surfelAreaTable(kSpacing);
    const double sx = kSpacing.x, sy = kSpacing.y, sz = kSpacing.z;
    const double triangle = std::sqrt(sx * sx * sy * sy + sy * sy * sz * sz + sx * sx * sz * sz) / 8.0;
    for (int k = 0; k < 8; ++k) EXPECT_NEAR(area[size_t(128 >> k)], triangle, 1e-14) << "corner " << k;
    const double rectangle = sx * 0.5 * std::sqrt(sy * sy + sz * sz);
    EXPECT_NEAR(area[codeOf({{0, 1, 1}, {1, 1, 1}})], rectangle, 1e-14);
    // Two corners on a face diagonal are cut off apart: two triangles.
    EXPECT_NEAR(area[codeOf({{0, 0, 0}, {1, 1, 0}})], 2.0 * triangle, 1e-14);
    // A corner and its three neighbours: the planar regular hexagon (unit spacing).
    const auto unit = surfelAreaTable(glm::dvec3(1.0));
    EXPECT_NEAR(unit[codeOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}})], 3.0 * std::sqrt(3.0) / 4.0,
                1e-14);
}

TEST(DeepmindSurfels, MatchBruteForce) {
    const std::array<int64_t, 3> dims{7, 6, 5};
    std::mt19937 rng(29);
    Volume v;
    v.dims = dims;
    v.labels.resize(size_t(dims[0] * dims[1] * dims[2]));
    for (auto& l : v.labels) l = (rng() % 100) < 40 ? 2 : int32_t(rng() % 2);
    auto selected = [&](int64_t i, int64_t j, int64_t k) {
        if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) return false;
        return v.labels[size_t(i + dims[0] * (j + dims[1] * k))] == 2;
    };
    std::vector<uint64_t> corners;
    std::vector<uint8_t> codes;
    for (int64_t k = 0; k <= dims[2]; ++k)
        for (int64_t j = 0; j <= dims[1]; ++j)
            for (int64_t i = 0; i <= dims[0]; ++i) {
                uint8_t code = 0;
                for (int a = 0; a < 2; ++a)
                    for (int b = 0; b < 2; ++b)
                        for (int c = 0; c < 2; ++c)
                            if (selected(i - 1 + a, j - 1 + b, k - 1 + c)) code |= neighbourBit(a, b, c);
                if (code == 0 || code == 255) continue;
                corners.push_back(uint64_t(i + (dims[0] + 1) * (j + (dims[1] + 1) * k)));
                codes.push_back(code);
            }
    const uint64_t count = uint64_t(std::count(v.labels.begin(), v.labels.end(), 2));
    for (int threads : {1, 2}) {
        const detail::Surfels s = detail::extractSurfels(v, LabelSelect{2, false}, threads);
        EXPECT_EQ(s.selected, count);
        EXPECT_EQ(s.corners, corners);
        EXPECT_EQ(s.codes, codes);
    }
}

TEST(DeepmindAreaWeighted, NumpySumIsPairwise) {
    // Under 8 values: a left-to-right loop.
    const std::vector<double> few{1e16, 1.0, 1.0, -1e16};
    EXPECT_EQ(detail::numpySum(few), ((1e16 + 1.0) + 1.0) - 1e16);
    // 16 values: eight partial sums r_j = x_j + x_(j+8), then ((r0+r1)+(r2+r3))+((r4+r5)+(r6+r7)).
    std::vector<double> x(16, 1.0);
    x[0] = 1e16;
    x[8] = -1e16;
    EXPECT_EQ(detail::numpySum(x), 14.0);  // numpy.sum gives 14; a left-to-right loop 7 (1e16 + 1 == 1e16)
    std::vector<double> left(x);
    EXPECT_EQ(std::accumulate(left.begin(), left.end(), 0.0), 7.0);
}

TEST(DeepmindAreaWeighted, FirstCumulativeFractionReachingP) {
    const std::vector<double> d{1.0, 2.0, 3.0};
    const std::vector<double> a{0.125, 0.125, 0.75};
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 0.0), 1.0);
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 12.5), 1.0);  // reached exactly at the first
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 12.6), 2.0);
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 25.0), 2.0);
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 25.1), 3.0);
    EXPECT_EQ(detail::areaWeightedPercentile(d, a, 100.0), 3.0);
    // Equal areas: the count's nearest rank, no interpolation.
    const std::vector<double> e{1.0, 2.0, 3.0, 4.0}, ones(4, 1.0);
    EXPECT_EQ(detail::areaWeightedPercentile(e, ones, 50.0), 2.0);
    EXPECT_EQ(detail::areaWeightedPercentile(e, ones, 50.1), 3.0);
    EXPECT_TRUE(std::isinf(detail::areaWeightedPercentile({}, {}, 50.0)));
}

Volume unitVolume(std::array<int64_t, 3> dims) {
    Volume v;
    v.dims = dims;
    v.labels.assign(size_t(dims[0] * dims[1] * dims[2]), 0);
    return v;
}

// Voxel (1, 1, 1) against voxel (4, 1, 1), unit spacing: each has 8 surfels
// (its corners, area sqrt(3)/8 each); A's four at x = 1.5 are 2 from B's at
// x = 3.5, its four at x = 0.5 are 3 away.
TEST(DeepmindBackend, OneVoxelEachByHand) {
    Options o;
    o.backend = backendUnderTest();
    Result<MaskEngine> engine = makeMaskEngine(o);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    Volume a = unitVolume({7, 3, 3}), b = a;
    a.labels[size_t(1 + 7 * (1 + 3 * 1))] = 1;
    b.labels[size_t(4 + 7 * (1 + 3 * 1))] = 1;
    MaskOptions mo;
    mo.convention = Convention::kDeepmind;
    mo.percentiles = {50.0, 50.5};
    mo.tolerance = 2.0;
    Result<MaskResult> r = compareMasks(*engine, a, {}, b, {}, mo);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->aToB.points, 8u);
    EXPECT_NEAR(r->aToB.area, std::sqrt(3.0), 1e-12);
    EXPECT_DOUBLE_EQ(r->hd, 3.0);
    EXPECT_DOUBLE_EQ(r->aToB.mean, 2.5);
    EXPECT_DOUBLE_EQ(r->msd, 2.5);
    EXPECT_DOUBLE_EQ(r->hdPercentile[0], 2.0);
    EXPECT_DOUBLE_EQ(r->hdPercentile[1], 3.0);
    EXPECT_DOUBLE_EQ(r->surfaceDice, 0.5);
    EXPECT_DOUBLE_EQ(r->aToB.surfaceOverlap, 0.5);
    EXPECT_EQ(r->aToB.voxel[0], 1);  // corner x = 1 sits at voxel coordinate 0.5
    EXPECT_EQ(r->aToB.nearestVoxel[0], 4);
}

TEST(DeepmindBackend, EmptyMasksReportInf) {
    Options o;
    o.backend = backendUnderTest();
    Result<MaskEngine> engine = makeMaskEngine(o);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    Volume empty = unitVolume({5, 5, 5}), one = empty;
    one.labels[62] = 1;
    MaskOptions mo;
    mo.convention = Convention::kDeepmind;
    Result<MaskResult> both = compareMasks(*engine, empty, {}, empty, {}, mo);
    ASSERT_TRUE(both.ok());
    EXPECT_EQ(both->empty, EmptyStatus::kBothEmpty);
    EXPECT_EQ(both->emptyValues.hd, "inf");
    EXPECT_EQ(both->emptyValues.surfaceDice, "nan");
    Result<MaskResult> bEmpty = compareMasks(*engine, one, {}, empty, {}, mo);
    ASSERT_TRUE(bEmpty.ok());
    EXPECT_EQ(bEmpty->empty, EmptyStatus::kBEmpty);
    EXPECT_EQ(bEmpty->emptyValues.hdPercentile.at(0), "inf");
    EXPECT_EQ(bEmpty->emptyValues.surfaceDice, "0");
    EXPECT_EQ(bEmpty->emptyValues.aToB.mean, "inf");
    EXPECT_EQ(bEmpty->emptyValues.bToA.mean, "nan");
    EXPECT_TRUE(std::isnan(bEmpty->hd));  // never a number folded into a mean
}

}  // namespace
}  // namespace rthdist::masks
