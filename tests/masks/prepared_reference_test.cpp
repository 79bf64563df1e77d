// The prepared reference (rthdist/masks.hpp PreparedReference): one reference
// prepared once and compared with many predictions gives, value for value,
// compareMasks(reference, prediction) in every convention, on the backend of
// RTHDIST_TEST_BACKEND (the *Backend* tests also run on ray-query and
// rt-pipeline: tests/masks/CMakeLists.txt).
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "masks_test_support.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

MaskEngine engineUnderTest() {
    Options o;
    o.backend = backendUnderTest();
    Result<MaskEngine> e = makeMaskEngine(o);
    EXPECT_TRUE(e.ok()) << e.error().message;
    return std::move(*e);
}

Volume grid(std::array<int64_t, 3> dims, const glm::dmat4& voxelToWorld, const std::string& path) {
    Volume v;
    v.path = path;
    v.dims = dims;
    v.voxelToWorld = voxelToWorld;
    v.labels.assign(size_t(dims[0] * dims[1] * dims[2]), 0);
    return v;
}

glm::dmat4 anisotropic() { return glm::scale(glm::dmat4(1.0), glm::dvec3(0.5, 0.7, 3.0)); }

// Rotated and sheared (the rthdist convention measures through it).
glm::dmat4 oblique() {
    glm::dmat4 m = glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(1.0, 2.0, 0.5)) * anisotropic();
    m[1][0] += 0.2;  // shear: column 1 gains an x component
    m[3] = glm::dvec4(-40.0, 12.5, 7.25, 1.0);
    return m;
}

size_t at(const Volume& v, int64_t i, int64_t j, int64_t k) {
    return size_t(i + v.dims[0] * (j + v.dims[1] * k));
}

// Label `label` on the ellipsoid of voxel radii r about c.
void ellipsoid(Volume& v, glm::dvec3 c, glm::dvec3 r, int32_t label) {
    for (int64_t k = 0; k < v.dims[2]; ++k)
        for (int64_t j = 0; j < v.dims[1]; ++j)
            for (int64_t i = 0; i < v.dims[0]; ++i) {
                const glm::dvec3 d = (glm::dvec3(double(i), double(j), double(k)) - c) / r;
                if (glm::dot(d, d) <= 1.0) v.labels[at(v, i, j, k)] = label;
            }
}

// Flips `count` random voxels to `label` or 0.
void noise(Volume& v, std::mt19937& rng, int count, int32_t label) {
    std::uniform_int_distribution<size_t> voxel(0, v.labels.size() - 1);
    for (int n = 0; n < count; ++n) {
        int32_t& l = v.labels[voxel(rng)];
        l = l == 0 ? label : 0;
    }
}

// The same label volume stored as 8-bit labels (the loaders' uint8 path).
Volume asLabels8(const Volume& v) {
    Volume out = v;
    out.labels8.assign(v.labels.begin(), v.labels.end());
    out.labels.clear();
    return out;
}

// Predictions of `ref` (whose label 1 is an ellipsoid about (14, 13, 5)):
// shifted, grown, shrunk, noisy, with an island, identical, disjoint, one
// voxel, empty, and 8-bit stored.
std::vector<Volume> predictions(const Volume& ref, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<Volume> out;
    auto blank = [&ref](const std::string& name) {
        Volume v = ref;
        v.path = name;
        std::fill(v.labels.begin(), v.labels.end(), 0);
        return v;
    };
    for (int n = 0; n < 6; ++n) {
        Volume p = blank("pred" + std::to_string(n));
        std::uniform_real_distribution<double> shift(-2.0, 2.0), radius(4.0, 8.0);
        ellipsoid(p, glm::dvec3(14 + shift(rng), 13 + shift(rng), 5 + 0.5 * shift(rng)),
                  glm::dvec3(radius(rng), radius(rng), 0.5 * radius(rng)), 1);
        if (n % 2 == 1) noise(p, rng, 40, 1);
        if (n == 4) ellipsoid(p, glm::dvec3(26, 3, 8), glm::dvec3(1.5), 1);  // an island
        out.push_back(std::move(p));
    }
    Volume same = ref;
    same.path = "identical";
    out.push_back(same);
    Volume disjoint = blank("disjoint");
    ellipsoid(disjoint, glm::dvec3(2, 2, 1), glm::dvec3(1.5, 1.5, 1.0), 1);
    out.push_back(disjoint);
    Volume one = blank("one_voxel");
    one.labels[at(one, 20, 7, 2)] = 1;
    out.push_back(one);
    out.push_back(blank("empty"));
    Volume bytes = asLabels8(out[1]);
    bytes.path = "labels8";
    out.push_back(bytes);
    return out;
}

// NaN equals NaN; everything else bit for bit as a double compares.
bool same(double x, double y) { return (std::isnan(x) && std::isnan(y)) || x == y; }

void expectSameDirected(const DirectedMask& x, const DirectedMask& y, const std::string& what) {
    EXPECT_EQ(x.points, y.points) << what;
    EXPECT_TRUE(same(x.hd, y.hd)) << what << ": hd " << x.hd << " vs " << y.hd;
    EXPECT_TRUE(same(x.mean, y.mean)) << what << ": mean " << x.mean << " vs " << y.mean;
    ASSERT_EQ(x.percentiles.size(), y.percentiles.size()) << what;
    for (size_t i = 0; i < x.percentiles.size(); ++i)
        EXPECT_TRUE(same(x.percentiles[i], y.percentiles[i])) << what << ": percentile " << i;
    EXPECT_TRUE(same(x.surfaceOverlap, y.surfaceOverlap)) << what;
    EXPECT_TRUE(same(x.area, y.area)) << what;
    EXPECT_EQ(x.voxel, y.voxel) << what;
    EXPECT_EQ(x.nearestVoxel, y.nearestVoxel) << what;
    for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(same(x.point[k], y.point[k])) << what;
        EXPECT_TRUE(same(x.nearestPoint[k], y.nearestPoint[k])) << what;
    }
}

// Every value of MaskResult (not the timings nor `extraction`).
void expectSameValues(const MaskResult& x, const MaskResult& y, const std::string& what) {
    EXPECT_EQ(x.convention, y.convention) << what;
    EXPECT_EQ(x.connectivity, y.connectivity) << what;
    EXPECT_EQ(x.empty, y.empty) << what;
    const EmptyValues &ex = x.emptyValues, &ey = y.emptyValues;
    EXPECT_EQ(ex.hd, ey.hd) << what;
    EXPECT_EQ(ex.hdPercentile, ey.hdPercentile) << what;
    EXPECT_EQ(ex.assd, ey.assd) << what;
    EXPECT_EQ(ex.msd, ey.msd) << what;
    EXPECT_EQ(ex.surfaceDice, ey.surfaceDice) << what;
    for (auto [dx, dy] : {std::pair{&ex.aToB, &ey.aToB}, std::pair{&ex.bToA, &ey.bToA}}) {
        EXPECT_EQ(dx->hd, dy->hd) << what;
        EXPECT_EQ(dx->mean, dy->mean) << what;
        EXPECT_EQ(dx->surfaceOverlap, dy->surfaceOverlap) << what;
        EXPECT_EQ(dx->percentiles, dy->percentiles) << what;
    }
    EXPECT_TRUE(same(x.hd, y.hd)) << what << ": hd " << x.hd << " vs " << y.hd;
    EXPECT_EQ(x.percentiles, y.percentiles) << what;
    ASSERT_EQ(x.hdPercentile.size(), y.hdPercentile.size()) << what;
    for (size_t i = 0; i < x.hdPercentile.size(); ++i)
        EXPECT_TRUE(same(x.hdPercentile[i], y.hdPercentile[i])) << what << ": hd percentile " << i;
    EXPECT_TRUE(same(x.assd, y.assd)) << what << ": assd " << x.assd << " vs " << y.assd;
    EXPECT_TRUE(same(x.msd, y.msd)) << what;
    EXPECT_TRUE(same(x.surfaceDice, y.surfaceDice)) << what;
    expectSameDirected(x.aToB, y.aToB, what + " a_to_b");
    expectSameDirected(x.bToA, y.bToA, what + " b_to_a");
}

// One prepared reference per convention, reused for every prediction.
void expectPreparedEqualsUnprepared(MaskEngine& engine, const Volume& ref, LabelSelect select,
                                    const std::vector<Volume>& preds, int connectivity) {
    for (Convention c : kAllConventions) {
        MaskOptions mo;
        mo.convention = c;
        mo.connectivity = connectivity;
        mo.percentiles = {95.0, 50.0, 100.0, 0.0};
        mo.tolerance = 1.2;
        Result<PreparedReference> prepared = prepareReference(engine, ref, select, mo);
        ASSERT_TRUE(prepared.ok()) << conventionName(c) << ": " << prepared.error().message;
        for (const Volume& p : preds) {
            const std::string what = std::string(conventionName(c)) + " vs " + p.path;
            Result<MaskResult> direct = compareMasks(engine, ref, select, p, select, mo);
            Result<MaskResult> reused = compareMasks(engine, *prepared, p, select, mo);
            ASSERT_TRUE(direct.ok()) << what << ": " << direct.error().message;
            ASSERT_TRUE(reused.ok()) << what << ": " << reused.error().message;
            expectSameValues(*reused, *direct, what);
            if (direct->empty == EmptyStatus::kNone)
                EXPECT_EQ(prepared->points(), direct->aToB.points) << what;
        }
    }
}

TEST(MasksPreparedBackend, EqualsUnpreparedAnisotropic) {
    MaskEngine engine = engineUnderTest();
    const unsigned seed = 20261126;
    SCOPED_TRACE("seed " + std::to_string(seed));
    Volume ref = grid({30, 28, 10}, anisotropic(), "ref");
    ellipsoid(ref, glm::dvec3(14, 13, 5), glm::dvec3(6.0, 5.0, 3.0), 1);
    ref.labels[at(ref, 1, 1, 1)] = 1;  // an outlier voxel
    const std::vector<Volume> preds = predictions(ref, seed);
    ASSERT_GE(preds.size(), 10u);
    expectPreparedEqualsUnprepared(engine, ref, {}, preds, 0);
}

TEST(MasksPreparedBackend, EqualsUnpreparedObliqueAnd26Connected) {
    MaskEngine engine = engineUnderTest();
    const unsigned seed = 7;
    SCOPED_TRACE("seed " + std::to_string(seed));
    Volume ref = grid({30, 28, 10}, oblique(), "ref_oblique");
    ellipsoid(ref, glm::dvec3(14, 13, 5), glm::dvec3(7.0, 4.0, 3.5), 1);
    std::vector<Volume> preds = predictions(ref, seed);
    for (Volume& p : preds) p.voxelToWorld = ref.voxelToWorld;
    expectPreparedEqualsUnprepared(engine, ref, {}, preds, 26);
}

TEST(MasksPreparedBackend, OneLabelOfSeveral) {
    MaskEngine engine = engineUnderTest();
    Volume ref = grid({24, 20, 12}, anisotropic(), "atlas_like");
    ellipsoid(ref, glm::dvec3(8, 10, 6), glm::dvec3(5.0, 6.0, 4.0), 3);
    ellipsoid(ref, glm::dvec3(17, 10, 6), glm::dvec3(4.0, 5.0, 4.0), 5);
    std::vector<Volume> preds;
    for (int n = 0; n < 3; ++n) {
        Volume p = ref;
        p.path = "labels" + std::to_string(n);
        std::mt19937 rng(unsigned(100 + n));
        noise(p, rng, 60, n == 0 ? 3 : 5);
        preds.push_back(n == 2 ? asLabels8(p) : p);
    }
    expectPreparedEqualsUnprepared(engine, ref, LabelSelect{5, false}, preds, 18);
}

TEST(MasksPreparedBackend, OneVoxelAndEmptyReferences) {
    MaskEngine engine = engineUnderTest();
    Volume one = grid({9, 8, 7}, anisotropic(), "one_voxel_ref");
    one.labels[at(one, 4, 3, 2)] = 1;
    Volume empty = grid({9, 8, 7}, anisotropic(), "empty_ref");
    Volume other = empty, ball = empty;
    other.path = "one_voxel_pred";
    other.labels[at(other, 0, 7, 6)] = 1;
    ball.path = "ball";
    ellipsoid(ball, glm::dvec3(4, 4, 3), glm::dvec3(3.0, 3.0, 2.0), 1);
    const std::vector<Volume> preds{other, one, empty, ball};
    expectPreparedEqualsUnprepared(engine, one, {}, preds, 0);
    expectPreparedEqualsUnprepared(engine, empty, {}, preds, 0);
}

TEST(MasksPrepared, KeepsAndReportsItsPoints) {
    MaskEngine engine = engineUnderTest();
    Volume ref = grid({20, 20, 10}, anisotropic(), "ref");
    ellipsoid(ref, glm::dvec3(10, 10, 5), glm::dvec3(6.0, 6.0, 3.0), 1);
    MaskOptions mo;
    mo.convention = Convention::kItk;
    Result<PreparedReference> itk = prepareReference(engine, ref, {}, mo);
    ASSERT_TRUE(itk.ok());
    EXPECT_EQ(itk->convention(), Convention::kItk);
    EXPECT_EQ(itk->connectivity(), 0);
    EXPECT_EQ(itk->points(), itk->selectedVoxels());
    // The bits (one per voxel) plus the boundary and its prepared set.
    EXPECT_GT(itk->hostBytes() + itk->deviceBytes(), ref.voxelCount() / 8);
    mo.convention = Convention::kMedpy;
    mo.connectivity = 18;
    Result<PreparedReference> medpy = prepareReference(engine, ref, {}, mo);
    ASSERT_TRUE(medpy.ok());
    EXPECT_EQ(medpy->connectivity(), 18);
    EXPECT_LT(medpy->points(), medpy->selectedVoxels());  // the boundary only
    EXPECT_GE(medpy->hostBytes(), medpy->points() * sizeof(uint64_t));
    EXPECT_EQ(medpy->grid().dims, ref.dims);
    EXPECT_TRUE(medpy->grid().labels.empty() && medpy->grid().labels8.empty());
    // A copy outlives the original and still compares.
    PreparedReference copy = *medpy;
    medpy = Error{ErrorCode::kInternal, "released"};
    Result<MaskResult> r = compareMasks(engine, copy, ref, {}, mo);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->hd, 0.0);
}

TEST(MasksPrepared, GridMismatchIsTheSameError) {
    MaskEngine engine = engineUnderTest();
    Volume ref = grid({12, 10, 8}, anisotropic(), "ref.nii.gz");
    ellipsoid(ref, glm::dvec3(6, 5, 4), glm::dvec3(3.0), 1);
    Volume dims = grid({12, 10, 9}, anisotropic(), "taller.nii.gz");
    Volume affine =
        grid({12, 10, 8}, glm::scale(glm::dmat4(1.0), glm::dvec3(0.5, 0.7, 2.0)), "thinner.nii.gz");
    for (Convention c : kAllConventions) {
        MaskOptions mo;
        mo.convention = c;
        Result<PreparedReference> prepared = prepareReference(engine, ref, {}, mo);
        ASSERT_TRUE(prepared.ok());
        for (const Volume* p : {&dims, &affine}) {
            Result<MaskResult> direct = compareMasks(engine, ref, {}, *p, {}, mo);
            Result<MaskResult> reused = compareMasks(engine, *prepared, *p, {}, mo);
            ASSERT_FALSE(direct.ok());
            ASSERT_FALSE(reused.ok()) << conventionName(c) << " vs " << p->path;
            EXPECT_EQ(reused.error().code, ErrorCode::kBadInput);
            EXPECT_EQ(reused.error().message, direct.error().message);
            EXPECT_NE(reused.error().message.find("ref.nii.gz"), std::string::npos);
            EXPECT_NE(reused.error().message.find(p->path), std::string::npos);
        }
    }
}

TEST(MasksPrepared, OptionsNeedingAnotherPointSetAreRefused) {
    MaskEngine engine = engineUnderTest();
    Volume ref = grid({12, 10, 8}, anisotropic(), "ref");
    ellipsoid(ref, glm::dvec3(6, 5, 4), glm::dvec3(4.0, 3.0, 2.0), 1);
    Volume pred = ref;
    pred.path = "pred";
    std::mt19937 rng(3);
    noise(pred, rng, 30, 1);
    MaskOptions mo;
    mo.convention = Convention::kMonai;
    Result<PreparedReference> monai = prepareReference(engine, ref, {}, mo);
    ASSERT_TRUE(monai.ok());
    // plastimatch and medpy (6) measure monai's boundary in the same metric: served.
    for (Convention c : {Convention::kPlastimatch, Convention::kMedpy}) {
        mo.convention = c;
        Result<MaskResult> reused = compareMasks(engine, *monai, pred, {}, mo);
        Result<MaskResult> direct = compareMasks(engine, ref, {}, pred, {}, mo);
        ASSERT_TRUE(reused.ok() && direct.ok()) << conventionName(c);
        expectSameValues(*reused, *direct, conventionName(c));
    }
    // Another connectivity, the world metric, all voxels, surfels: refused.
    const std::pair<Convention, int> refused[] = {{Convention::kMedpy, 18},
                                                  {Convention::kRthdist, 6},
                                                  {Convention::kItk, 0},
                                                  {Convention::kDeepmind, 0}};
    for (auto [c, conn] : refused) {
        mo.convention = c;
        mo.connectivity = conn;
        Result<MaskResult> r = compareMasks(engine, *monai, pred, {}, mo);
        ASSERT_FALSE(r.ok()) << conventionName(c);
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
        EXPECT_NE(r.error().message.find("prepared for convention 'monai'"), std::string::npos)
            << r.error().message;
        EXPECT_NE(r.error().message.find(std::string("'") + conventionName(c) + "'"), std::string::npos)
            << r.error().message;
    }
    // Bad options and label arrays: compareMasks's errors.
    mo.convention = Convention::kMonai;
    mo.connectivity = 0;
    mo.percentiles = {101.0};
    EXPECT_FALSE(compareMasks(engine, *monai, pred, {}, mo).ok());
    EXPECT_FALSE(prepareReference(engine, ref, {}, mo).ok());
    mo.percentiles = {95.0};
    pred.labels.pop_back();
    Result<MaskResult> shortLabels = compareMasks(engine, *monai, pred, {}, mo);
    ASSERT_FALSE(shortLabels.ok());
    EXPECT_EQ(shortLabels.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace rthdist::masks
