// The test cases of the tools rthdist-masks reproduces, ported: their inputs
// and expected values re-expressed here (no code of theirs), for the 3-D
// Euclidean metrics, on the backend of RTHDIST_TEST_BACKEND (suites named
// *Backend* run on cpu, ray-query and rt-pipeline):
//   DeepMind surface-distance (1f805ce) surface_distance_test.py,
//     SurfaceDistance3DTest: A = mask_gt, B = mask_pred, convention deepmind.
//   MONAI (d388d1c) tests/metrics/test_hausdorff_distance.py (euclidean,
//     directed and not), test_surface_distance.py (euclidean, symmetric and
//     not), test_surface_dice.py (the 3-D case; the presence case in 3-D):
//     A = y_pred, B = y, convention monai.
//   MedPy (loli/medpy) tests/metric_/binary.py (asd, assd; 1-D and 2-D
//     arrays as 3-D volumes with unit axes, which keeps every voxel a
//     boundary voxel as in their dimension): A = result, B = reference.
// Then the MONAI behaviours its tests do not pin: surface-Dice distances
// compared in float32, the quantile rank in float32, the maximum for
// percentile 0; and what each convention reports for empty masks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <string>

#include "masks_test_support.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

MaskEngine engineUnderTest() {
    Options o;
    o.backend = backendUnderTest();
    Result<MaskEngine> e = makeMaskEngine(o);
    if (!e.ok()) {
        ADD_FAILURE() << e.error().message;
        std::abort();
    }
    return std::move(*e);
}

using Inside = std::function<bool(int64_t, int64_t, int64_t)>;

// A volume of `dims` (array axes 0, 1, 2 = i, j, k) with `spacing`, label 1
// where `inside` holds, 0 elsewhere.
Volume volume(std::array<int64_t, 3> dims, glm::dvec3 spacing, const Inside& inside) {
    Volume v;
    v.path = "peer case";
    v.dims = dims;
    v.voxelToWorld = glm::dmat4(1.0);
    v.voxelToWorld[0][0] = spacing.x;
    v.voxelToWorld[1][1] = spacing.y;
    v.voxelToWorld[2][2] = spacing.z;
    v.labels.assign(size_t(dims[0] * dims[1] * dims[2]), 0);
    for (int64_t k = 0; k < dims[2]; ++k)
        for (int64_t j = 0; j < dims[1]; ++j)
            for (int64_t i = 0; i < dims[0]; ++i)
                if (inside(i, j, k)) v.labels[size_t(i + dims[0] * (j + dims[1] * k))] = 1;
    return v;
}

Inside nothing() {
    return [](int64_t, int64_t, int64_t) { return false; };
}

// MONAI's create_spherical_seg_3d: voxel (i, j, k) is inside when
// (x1^2 + x0^2) + x2^2 <= r^2 with x_a = index_a * spacing_a - centre_a,
// summed in the order its NumPy expression sums.
Inside monaiSphere(double radius, glm::dvec3 centre, glm::dvec3 spacing = glm::dvec3(1.0)) {
    return [=](int64_t i, int64_t j, int64_t k) {
        const double y = double(i) * spacing.x - centre.x;
        const double x = double(j) * spacing.y - centre.y;
        const double z = double(k) * spacing.z - centre.z;
        return x * x + y * y + z * z <= radius * radius;
    };
}

MaskResult compare(MaskEngine& engine, const Volume& a, const Volume& b, const MaskOptions& o) {
    Result<MaskResult> r = compareMasks(engine, a, {}, b, {}, o);
    if (!r.ok()) {
        ADD_FAILURE() << r.error().message;
        return {};
    }
    return std::move(*r);
}

MaskOptions optionsOf(Convention c, std::vector<double> percentiles = {95.0}, double tolerance = 1.0) {
    MaskOptions o;
    o.convention = c;
    o.percentiles = std::move(percentiles);
    o.tolerance = tolerance;
    return o;
}

// numpy.testing.assert_allclose(expected, actual, rtol).
void expectClose(double actual, double expected, double rtol, const std::string& what) {
    EXPECT_LE(std::abs(actual - expected), rtol * std::abs(expected))
        << what << ": " << actual << " vs " << expected;
}

// absltest's assertAlmostEqual(places=3): round(|a - b|, 3) == 0.
void expectPlaces3(double actual, double expected, const std::string& what) {
    EXPECT_LT(std::abs(actual - expected), 5e-4) << what << ": " << actual << " vs " << expected;
}

// ---------------------------------------------------------------- DeepMind

TEST(PeerDeepmindBackend, OnTwoPixels2mmAway) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 s(3, 2, 1);
    const Volume gt = volume({128, 128, 128}, s,
                             [](int64_t i, int64_t j, int64_t k) { return i == 50 && j == 60 && k == 70; });
    const Volume pred = volume({128, 128, 128}, s,
                               [](int64_t i, int64_t j, int64_t k) { return i == 50 && j == 60 && k == 72; });
    const MaskResult r = compare(engine, gt, pred, optionsOf(Convention::kDeepmind, {100.0, 95.0}));
    ASSERT_EQ(r.empty, EmptyStatus::kNone);
    expectPlaces3(r.aToB.mean, 1.5, "average gt->pred");
    expectPlaces3(r.bToA.mean, 1.5, "average pred->gt");
    expectPlaces3(r.hdPercentile[0], 2.0, "robust HD 100");
    expectPlaces3(r.hd, 2.0, "HD");
    expectPlaces3(r.hdPercentile[1], 2.0, "robust HD 95");
    expectPlaces3(r.aToB.surfaceOverlap, 0.5, "overlap gt");
    expectPlaces3(r.bToA.surfaceOverlap, 0.5, "overlap pred");
    expectPlaces3(r.surfaceDice, 0.5, "surface Dice at 1 mm");
}

TEST(PeerDeepmindBackend, TwoCubesShiftedByOnePixel) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 s(2, 1, 1);
    const Volume gt = volume({100, 100, 100}, s, [](int64_t i, int64_t, int64_t) { return i < 50; });
    const Volume pred = volume({100, 100, 100}, s, [](int64_t i, int64_t, int64_t) { return i < 51; });
    const MaskResult r = compare(engine, gt, pred, optionsOf(Convention::kDeepmind, {100.0, 95.0}));
    ASSERT_EQ(r.empty, EmptyStatus::kNone);
    expectPlaces3(r.aToB.mean, 0.322, "average gt->pred");
    expectPlaces3(r.bToA.mean, 0.339, "average pred->gt");
    expectPlaces3(r.hdPercentile[0], 2.0, "robust HD 100");
    expectPlaces3(r.hdPercentile[1], 2.0, "robust HD 95");
    expectPlaces3(r.aToB.surfaceOverlap, 0.842, "overlap gt");
    expectPlaces3(r.bToA.surfaceOverlap, 0.830, "overlap pred");
    expectPlaces3(r.surfaceDice, 0.836, "surface Dice at 1 mm");
}

// DeepMind's expectations for empty masks, in rthdist's texts.
struct DeepmindEmpty {
    const char *averageGt, *averagePred, *overlapGt, *overlapPred, *dice;
};

void expectDeepmindEmpty(const MaskResult& r, const DeepmindEmpty& e) {
    const EmptyValues& v = r.emptyValues;
    EXPECT_EQ(v.aToB.mean, e.averageGt);
    EXPECT_EQ(v.bToA.mean, e.averagePred);
    EXPECT_EQ(v.hd, "inf");  // robust HD 100
    ASSERT_EQ(v.hdPercentile.size(), 2u);
    EXPECT_EQ(v.hdPercentile[0], "inf");
    EXPECT_EQ(v.hdPercentile[1], "inf");  // robust HD 95
    EXPECT_EQ(v.aToB.surfaceOverlap, e.overlapGt);
    EXPECT_EQ(v.bToA.surfaceOverlap, e.overlapPred);
    EXPECT_EQ(v.surfaceDice, e.dice);
}

TEST(PeerDeepmindBackend, EmptyMasks) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 s(3, 2, 1);
    const Volume empty = volume({128, 128, 128}, s, nothing());
    const Volume gt = volume({128, 128, 128}, s,
                             [](int64_t i, int64_t j, int64_t k) { return i == 50 && j == 60 && k == 70; });
    const Volume pred = volume({128, 128, 128}, s,
                               [](int64_t i, int64_t j, int64_t k) { return i == 50 && j == 60 && k == 72; });
    const MaskOptions o = optionsOf(Convention::kDeepmind, {100.0, 95.0});
    const MaskResult noPred = compare(engine, gt, empty, o);
    EXPECT_EQ(noPred.empty, EmptyStatus::kBEmpty);
    expectDeepmindEmpty(noPred, {"inf", "nan", "0", "nan", "0"});
    EXPECT_EQ(noPred.aToB.points, 8u);  // the voxel's eight corners
    EXPECT_EQ(noPred.bToA.points, 0u);
    const MaskResult noGt = compare(engine, empty, pred, o);
    EXPECT_EQ(noGt.empty, EmptyStatus::kAEmpty);
    expectDeepmindEmpty(noGt, {"nan", "inf", "nan", "0", "0"});
    EXPECT_EQ(noGt.aToB.points, 0u);
    EXPECT_EQ(noGt.bToA.points, 8u);
    const MaskResult none = compare(engine, empty, empty, o);
    EXPECT_EQ(none.empty, EmptyStatus::kBothEmpty);
    expectDeepmindEmpty(none, {"nan", "nan", "nan", "nan", "nan"});
}

// ---------------------------------------------------------------- MONAI

// One row of test_hausdorff_distance.py's TEST_CASES: the euclidean values,
// directed (y_pred -> y) and not.
struct MonaiHdCase {
    const char* name;
    Inside pred, gt;
    glm::dvec3 spacing;
    double percentile;  // 0: none (the maximum)
    double directed, undirected;
};

TEST(PeerMonaiBackend, HausdorffDistanceEuclidean) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 one(1.0), sp(0.85, 1.2, 0.9);
    const double inf = std::numeric_limits<double>::infinity();
    const MonaiHdCase cases[] = {
        {"same sphere", monaiSphere(20, {49, 49, 49}), monaiSphere(20, {49, 49, 49}), one, 0, 0, 0},
        {"r20 shifted (1,1,1)", monaiSphere(20, {20, 20, 20}), monaiSphere(20, {19, 19, 19}), one, 0,
         1.7320508075688772, 1.7320508075688772},
        {"r33 shifted 1", monaiSphere(33, {19, 33, 22}), monaiSphere(33, {20, 33, 22}), one, 0, 1, 1},
        {"r20 in r40", monaiSphere(20, {20, 33, 22}), monaiSphere(40, {20, 33, 22}), one, 0,
         20.09975124224178, 20.223748416156685},
        {"empty pred", nothing(), monaiSphere(40, {20, 33, 22}), one, 0, inf, inf},
        {"empty gt", monaiSphere(20, {49, 49, 49}), nothing(), one, 0, inf, inf},
        {"r20 in r40, HD95", monaiSphere(20, {20, 33, 22}), monaiSphere(40, {20, 33, 22}), one, 95,
         19.924858845171276, 20.09975124224178},
        {"spacing, r20 shifted", monaiSphere(20, {20, 20, 20}, sp), monaiSphere(20, {19, 19, 19}, sp), sp, 0,
         2.0808651447296143, 2.2671568},
        {"spacing, r15 in r30", monaiSphere(15, {20, 33, 22}, sp), monaiSphere(30, {20, 33, 22}, sp), sp, 0,
         15.439640998840332, 15.62594},
    };
    for (const MonaiHdCase& c : cases) {
        const Volume pred = volume({99, 99, 99}, c.spacing, c.pred);
        const Volume gt = volume({99, 99, 99}, c.spacing, c.gt);
        const bool p = c.percentile > 0;
        const MaskResult r =
            compare(engine, pred, gt, optionsOf(Convention::kMonai, {p ? c.percentile : 95.0}));
        if (std::isinf(c.directed)) {
            ASSERT_NE(r.empty, EmptyStatus::kNone) << c.name;
            EXPECT_EQ(r.emptyValues.aToB.hd, "inf") << c.name;
            EXPECT_EQ(r.emptyValues.hd, "inf") << c.name;
            continue;
        }
        ASSERT_EQ(r.empty, EmptyStatus::kNone) << c.name;
        expectClose(p ? r.aToB.percentiles[0] : r.aToB.hd, c.directed, 1e-6,
                    std::string(c.name) + " directed");
        expectClose(p ? r.hdPercentile[0] : r.hd, c.undirected, 1e-6, std::string(c.name) + " undirected");
    }
}

// TEST_CASES_NANS of the Hausdorff and surface distance tests: no
// foreground anywhere -> NaN (not counted by MONAI's aggregate).
TEST(PeerMonaiBackend, BothEmptyIsNan) {
    MaskEngine engine = engineUnderTest();
    for (glm::dvec3 s : {glm::dvec3(1.0), glm::dvec3(0.85, 1.2, 0.9)}) {
        const Volume empty = volume({99, 99, 99}, s, nothing());
        const MaskResult r = compare(engine, empty, empty, optionsOf(Convention::kMonai, {95.0, 0.0}));
        EXPECT_EQ(r.empty, EmptyStatus::kBothEmpty);
        const EmptyValues& v = r.emptyValues;
        for (const std::string& t :
             {v.hd, v.assd, v.surfaceDice, v.aToB.hd, v.aToB.mean, v.hdPercentile[0], v.hdPercentile[1]})
            EXPECT_EQ(t, "nan");
    }
}

// test_surface_distance.py's euclidean rows: [symmetric, directed].
TEST(PeerMonaiBackend, SurfaceDistanceEuclidean) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 one(1.0), sp(0.85, 1.2, 0.9);
    struct Case {
        const char* name;
        Inside pred, gt;
        glm::dvec3 spacing;
        double symmetric, directed, rtol;
    };
    const Case cases[] = {
        {"same sphere", monaiSphere(20, {49, 49, 49}), monaiSphere(20, {49, 49, 49}), one, 0, 0, 1e-5},
        {"r33 shifted 1", monaiSphere(33, {19, 33, 22}), monaiSphere(33, {20, 33, 22}), one, 0.350217,
         0.3483278807706289, 1e-5},
        {"r20 in r40", monaiSphere(20, {20, 33, 22}), monaiSphere(40, {20, 33, 22}), one, 15.117741,
         12.040033513150455, 1e-5},
        {"spacing, r33 shifted 1", monaiSphere(33, {42, 45, 52}, sp), monaiSphere(33, {43, 45, 52}, sp), sp,
         0.4951, 0.4951, 1e-5},
    };
    for (const Case& c : cases) {
        const MaskResult r = compare(engine, volume({99, 99, 99}, c.spacing, c.pred),
                                     volume({99, 99, 99}, c.spacing, c.gt), optionsOf(Convention::kMonai));
        ASSERT_EQ(r.empty, EmptyStatus::kNone) << c.name;
        if (c.symmetric == 0) {
            EXPECT_EQ(r.assd, 0.0) << c.name;
            EXPECT_EQ(r.aToB.mean, 0.0) << c.name;
            continue;
        }
        expectClose(r.assd, c.symmetric, c.rtol, std::string(c.name) + " symmetric");
        expectClose(r.aToB.mean, c.directed, c.rtol, std::string(c.name) + " directed");
    }
    // One mask without foreground: inf, symmetric or not (their euclidean
    // and taxicab rows; the value does not depend on the metric).
    for (bool predEmpty : {true, false}) {
        const Volume pred = volume({99, 99, 99}, one, predEmpty ? nothing() : monaiSphere(20, {49, 49, 49}));
        const Volume gt = volume({99, 99, 99}, one, predEmpty ? monaiSphere(40, {20, 33, 22}) : nothing());
        const MaskResult r = compare(engine, pred, gt, optionsOf(Convention::kMonai));
        EXPECT_EQ(r.empty, predEmpty ? EmptyStatus::kAEmpty : EmptyStatus::kBEmpty);
        EXPECT_EQ(r.emptyValues.assd, "inf");
        EXPECT_EQ(r.emptyValues.aToB.mean, "inf");
    }
}

// test_surface_dice.py, test_tolerance_euclidean_distance_3d: two slabs of a
// 200 x 110 x 80 volume offset by 10 voxels along the last axis; class 1 is
// the slab (label 1), class 0 the background (label 0); batch item 1 has no
// foreground at all.
TEST(PeerMonaiBackend, SurfaceDice3d) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 one(1.0);
    const Volume pred = volume({200, 110, 80}, one, [](int64_t, int64_t, int64_t k) { return k >= 20; });
    const Volume gt = volume({200, 110, 80}, one, [](int64_t, int64_t, int64_t k) { return k >= 30; });
    const LabelSelect cls1{1, false}, cls0{0, false};
    auto dice = [&](LabelSelect c, double tolerance) {
        Result<MaskResult> r =
            compareMasks(engine, pred, c, gt, c, optionsOf(Convention::kMonai, {95}, tolerance));
        EXPECT_TRUE(r.ok()) << r.error().message;
        return r.ok() ? r->surfaceDice : std::nan("");
    };
    const double res0c1 = 1.0 - double(200 * 110 + 198 * 108 + 9 * 200 * 2 + 9 * 108 * 2) /
                                    double(200 * 110 * 4 + (58 + 48) * 200 * 2 + (58 + 48) * 108 * 2);
    const double res0c0 = 1.0 - double(200 * 110 + 198 * 108 + 9 * 200 * 2 + 9 * 108 * 2) /
                                    double(200 * 110 * 4 + (28 + 18) * 200 * 2 + (28 + 18) * 108 * 2);
    const double d0c1 = dice(cls1, 0), d0c0 = dice(cls0, 0);
    expectClose(d0c1, res0c1, 1e-7, "class 1 at 0");
    expectClose(d0c0, res0c0, 1e-7, "class 0 at 0");
    const double d1c1 = dice(cls1, 1), d10c1 = dice(cls1, 10), d11c1 = dice(cls1, 11);
    EXPECT_LT(d0c1, d1c1);
    EXPECT_LT(d1c1, d10c1);
    EXPECT_EQ(d10c1, d11c1);
    const double d1c0 = dice(cls0, 1), d10c0 = dice(cls0, 10), d11c0 = dice(cls0, 11);
    EXPECT_LT(d0c0, d1c0);
    EXPECT_LT(d1c0, d10c0);
    EXPECT_EQ(d10c0, d11c0);
    // Batch item 1: class 0 fills both volumes (1), class 1 is in neither (NaN).
    const Volume zeros = volume({200, 110, 80}, one, nothing());
    Result<MaskResult> full = compareMasks(engine, zeros, cls0, zeros, cls0, optionsOf(Convention::kMonai));
    ASSERT_TRUE(full.ok());
    EXPECT_EQ(full->surfaceDice, 1.0);
    Result<MaskResult> none = compareMasks(engine, zeros, cls1, zeros, cls1, optionsOf(Convention::kMonai));
    ASSERT_TRUE(none.ok());
    EXPECT_EQ(none->empty, EmptyStatus::kBothEmpty);
    EXPECT_EQ(none->emptyValues.surfaceDice, "nan");
}

// test_not_predicted_not_present, in 3-D: a class in both (1), in the
// prediction only or the reference only (0), in neither (NaN).
TEST(PeerMonaiBackend, SurfaceDiceNotPredictedNotPresent) {
    MaskEngine engine = engineUnderTest();
    auto cube = [](int32_t label) {
        Volume v = volume({40, 40, 40}, glm::dvec3(1.0), [](int64_t i, int64_t j, int64_t k) {
            return i >= 10 && i < 20 && j >= 10 && j < 20 && k >= 10 && k < 20;
        });
        for (int32_t& l : v.labels) l *= label;
        return v;
    };
    const Volume pred = cube(1), gt = cube(2);
    const double expected[] = {1.0, 0.0, 0.0, std::nan("")};
    for (int32_t c = 0; c < 4; ++c) {
        const LabelSelect s{c, false};
        Result<MaskResult> r = compareMasks(engine, pred, s, gt, s, optionsOf(Convention::kMonai, {95}, 1.0));
        ASSERT_TRUE(r.ok());
        if (c == 0) {
            EXPECT_EQ(r->surfaceDice, expected[0]);
        } else {
            ASSERT_NE(r->empty, EmptyStatus::kNone) << c;
            EXPECT_EQ(r->emptyValues.surfaceDice, c == 3 ? "nan" : "0") << c;
        }
    }
}

// ---------------------------------------------------------------- MedPy

TEST(PeerMedpyBackend, AsdAssd) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 one(1.0);
    // result_min = [1, 0], reference_min = [0, 1].
    const Volume rMin = volume({2, 1, 1}, one, [](int64_t i, int64_t, int64_t) { return i == 0; });
    const Volume refMin = volume({2, 1, 1}, one, [](int64_t i, int64_t, int64_t) { return i == 1; });
    const MaskOptions o = optionsOf(Convention::kMedpy);
    const MaskResult same = compare(engine, rMin, rMin, o);
    EXPECT_EQ(same.aToB.mean, 0.0);  // asd identity
    EXPECT_EQ(same.assd, 0.0);       // assd identity
    const MaskResult apart = compare(engine, rMin, refMin, o);
    EXPECT_EQ(apart.aToB.mean, 1.0);
    EXPECT_EQ(apart.assd, 1.0);
    // voxelspacing=[2].
    const Volume rMin2 =
        volume({2, 1, 1}, glm::dvec3(2.0), [](int64_t i, int64_t, int64_t) { return i == 0; });
    const Volume refMin2 =
        volume({2, 1, 1}, glm::dvec3(2.0), [](int64_t i, int64_t, int64_t) { return i == 1; });
    const MaskResult spaced = compare(engine, rMin2, refMin2, o);
    EXPECT_EQ(spaced.aToB.mean, 2.0);
    EXPECT_EQ(spaced.assd, 2.0);
    // result_sym / reference_sym (4 x 4): asd is not symmetric, assd is.
    const int resultSym[4][4] = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {1, 1, 0, 0}};
    const int referenceSym[4][4] = {{1, 1, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}};
    const Volume rSym =
        volume({4, 4, 1}, one, [&](int64_t i, int64_t j, int64_t) { return resultSym[i][j]; });
    const Volume refSym =
        volume({4, 4, 1}, one, [&](int64_t i, int64_t j, int64_t) { return referenceSym[i][j] != 0; });
    const MaskResult ab = compare(engine, rSym, refSym, o), ba = compare(engine, refSym, rSym, o);
    EXPECT_NE(ab.aToB.mean, ba.aToB.mean);
    EXPECT_EQ(ab.assd, ba.assd);
    // Their values from MedPy's definitions (every voxel is a border voxel):
    // result -> reference 0, 0, 0, 1, sqrt 2; reference -> result 0, 1, 0, 0.
    const double r2 = std::sqrt(2.0);
    EXPECT_NEAR(ab.aToB.mean, (1.0 + r2) / 5.0, 1e-15);
    EXPECT_NEAR(ba.aToB.mean, 0.25, 1e-15);
    EXPECT_NEAR(ab.assd, (2.0 + r2) / 9.0, 1e-15);
    EXPECT_NEAR(ab.hd, r2, 1e-15);  // hd
    // hd95: numpy.percentile of the nine pooled distances, rank 0.95 * 8.
    EXPECT_NEAR(ab.hdPercentile[0], 1.0 + 0.6 * (r2 - 1.0), 1e-15);
}

TEST(PeerMedpyBackend, EmptyMaskRaises) {
    MaskEngine engine = engineUnderTest();
    const Volume empty = volume({4, 4, 4}, glm::dvec3(1.0), nothing());
    const Volume one = volume({4, 4, 4}, glm::dvec3(1.0),
                              [](int64_t i, int64_t j, int64_t k) { return i == 1 && j == 2 && k == 1; });
    const MaskResult r = compare(engine, one, empty, optionsOf(Convention::kMedpy));
    EXPECT_EQ(r.empty, EmptyStatus::kBEmpty);
    for (const std::string& t : {r.emptyValues.hd, r.emptyValues.hdPercentile[0], r.emptyValues.assd,
                                 r.emptyValues.aToB.mean, r.emptyValues.bToA.hd})
        EXPECT_EQ(t, "error");
    EXPECT_EQ(r.aToB.points, 1u);
    EXPECT_EQ(r.bToA.points, 0u);
}

// ------------------------------------------- MONAI's float32 and p = 0

// Two slabs 3 voxels apart at 0.8 mm: every distance is 3 x 0.8 mm or less,
// and 3 x 0.8 is 2.4000000000000004 in double but 2.4f in float32, MONAI's
// distances' type: at a tolerance of 2.4 mm MONAI counts them all.
TEST(PeerMonaiFloat32Backend, SurfaceDiceComparesInFloat32) {
    MaskEngine engine = engineUnderTest();
    const glm::dvec3 s(0.8);
    const Volume a = volume({20, 20, 20}, s, [](int64_t, int64_t, int64_t k) { return k >= 5 && k < 12; });
    const Volume b = volume({20, 20, 20}, s, [](int64_t, int64_t, int64_t k) { return k >= 8 && k < 15; });
    MaskOptions o = optionsOf(Convention::kMonai, {95.0}, 2.4);
    const MaskResult f32 = compare(engine, a, b, o);
    EXPECT_EQ(f32.surfaceDice, 1.0);
    EXPECT_EQ(f32.aToB.surfaceOverlap, 1.0);
    EXPECT_EQ(f32.bToA.surfaceOverlap, 1.0);
    o.monaiFloat32 = false;
    const MaskResult f64 = compare(engine, a, b, o);
    const MaskResult own = compare(engine, a, b, optionsOf(Convention::kRthdist, {95.0}, 2.4));
    EXPECT_LT(f64.surfaceDice, 0.7);
    EXPECT_EQ(f64.surfaceDice, own.surfaceDice);  // the same distances, compared in double
}

// A = B plus one voxel 24 voxels away: A -> B is 488 zeros and one 24.
Volume cubeB() {
    return volume({40, 16, 16}, glm::dvec3(1.0), [](int64_t i, int64_t j, int64_t k) {
        return i >= 2 && i < 12 && j >= 2 && j < 12 && k >= 2 && k < 12;
    });
}
Volume cubeA() {
    Volume v = cubeB();
    v.labels[size_t(35 + 40 * (7 + 16 * 7))] = 1;
    return v;
}

TEST(PeerMonaiFloat32Backend, QuantileRankInFloat32) {
    MaskEngine engine = engineUnderTest();
    const Volume a = cubeA(), b = cubeB();
    MaskOptions o = optionsOf(Convention::kMonai, {99.9});
    const MaskResult f32 = compare(engine, a, b, o);
    ASSERT_EQ(f32.aToB.points, 489u);
    ASSERT_EQ(f32.aToB.hd, 24.0);
    // torch.quantile on float32: rank float(0.999) * 488.0f = 487.512f
    // (487.511993408203125), weight 0.511993408203125 of the 24 above the 0.
    const double weight = 0.511993408203125;
    EXPECT_EQ(f32.aToB.percentiles[0], 24.0 * weight);
    EXPECT_EQ(f32.hdPercentile[0], 24.0 * weight);
    o.monaiFloat32 = false;  // numpy's rank 0.999 * 488 = 487.512 in double
    const MaskResult f64 = compare(engine, a, b, o);
    EXPECT_NEAR(f64.hdPercentile[0], 24.0 * 0.512, 1e-9);
    EXPECT_GT(std::abs(f64.hdPercentile[0] - f32.hdPercentile[0]), 1e-4);
}

TEST(PeerMonaiFloat32Backend, PercentileZeroIsTheMaximum) {
    MaskEngine engine = engineUnderTest();
    const Volume a = cubeA(), b = cubeB();
    for (bool f32 : {true, false}) {
        MaskOptions o = optionsOf(Convention::kMonai, {0.0, 50.0});
        o.monaiFloat32 = f32;
        const MaskResult r = compare(engine, a, b, o);
        EXPECT_EQ(r.aToB.percentiles[0], 24.0);  // `if not percentile`: the maximum
        EXPECT_EQ(r.hdPercentile[0], 24.0);
        EXPECT_EQ(r.hdPercentile[1], 0.0);
        EXPECT_EQ(r.bToA.percentiles[0], 0.0);
    }
    // Other conventions keep their own rule: the least distance.
    const MaskResult medpy = compare(engine, a, b, optionsOf(Convention::kMedpy, {0.0}));
    EXPECT_EQ(medpy.hdPercentile[0], 0.0);
}

// ------------------------------------------------- empty masks, every tool

TEST(PeerEmptyBackend, EveryConventionReportsBothSidesPoints) {
    MaskEngine engine = engineUnderTest();
    const Volume empty = volume({12, 12, 12}, glm::dvec3(1.0), nothing());
    const Volume cube = volume({12, 12, 12}, glm::dvec3(1.0), [](int64_t i, int64_t j, int64_t k) {
        return i >= 3 && i < 7 && j >= 3 && j < 7 && k >= 3 && k < 7;
    });
    // The 4 x 4 x 4 cube's points: 56 boundary voxels, 64 voxels (itk), 98
    // surfel corners (deepmind: the 5 x 5 x 5 corners around it but the 3 x 3 x 3 inside).
    for (Convention c : kAllConventions) {
        const uint64_t n = c == Convention::kItk ? 64 : c == Convention::kDeepmind ? 98 : 56;
        const MaskOptions o = optionsOf(c, {95.0, 0.0});
        const MaskResult ab = compare(engine, cube, empty, o);
        EXPECT_EQ(ab.empty, EmptyStatus::kBEmpty) << conventionName(c);
        EXPECT_EQ(ab.aToB.points, n) << conventionName(c);
        EXPECT_EQ(ab.bToA.points, 0u) << conventionName(c);
        const MaskResult ba = compare(engine, empty, cube, o);
        EXPECT_EQ(ba.aToB.points, 0u) << conventionName(c);
        EXPECT_EQ(ba.bToA.points, n) << conventionName(c);
        EXPECT_TRUE(std::isnan(ab.hd)) << conventionName(c);  // never a number: the texts say
        EXPECT_FALSE(ab.emptyValues.hd.empty()) << conventionName(c);
    }
}

TEST(PeerEmptyBackend, MonaiOneEmpty) {
    MaskEngine engine = engineUnderTest();
    const Volume empty = volume({12, 12, 12}, glm::dvec3(1.0), nothing());
    const Volume cube = volume({12, 12, 12}, glm::dvec3(1.0), [](int64_t i, int64_t j, int64_t k) {
        return i >= 3 && i < 7 && j >= 3 && j < 7 && k >= 3 && k < 7;
    });
    for (bool aEmpty : {true, false}) {
        const MaskResult r = compare(engine, aEmpty ? empty : cube, aEmpty ? cube : empty,
                                     optionsOf(Convention::kMonai, {95.0, 0.0}));
        const EmptyValues& v = r.emptyValues;
        EXPECT_EQ(v.hd, "inf");
        EXPECT_EQ(v.hdPercentile, (std::vector<std::string>{"nan", "inf"}));
        EXPECT_EQ(v.assd, "inf");
        EXPECT_EQ(v.surfaceDice, "0");
        for (const EmptyDirected* d : {&v.aToB, &v.bToA}) {
            EXPECT_EQ(d->hd, "inf");  // directed=True: inf whichever side is empty
            EXPECT_EQ(d->mean, "inf");
            EXPECT_EQ(d->percentiles, (std::vector<std::string>{"nan", "inf"}));
        }
    }
}

}  // namespace
}  // namespace rthdist::masks
