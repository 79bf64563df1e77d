// rthdist_masks: loaders, grid checks, boundary extraction against a brute
// force, and compareMasks on every backend against the CPU backend. The
// conventions' numbers are checked against NumPy/SciPy in oracle_masks.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include "masks/boundary.hpp"
#include "masks/gpu_boundary.hpp"
#include "masks_gpu/boundary_pass.hpp"
#include "masks_test_support.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

const std::string kNifti = RTHDIST_SHARED_NIFTI_DIR;

std::string tempPath(const std::string& name) {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir ? dir : "/tmp") + "/rthdist_masks_test_" + std::to_string(::getpid()) + "_" + name;
}

// A .npy (format 1.0) of int16 with the given shape and order.
void writeNpy(const std::string& path, const std::vector<int16_t>& data, int64_t n0, int64_t n1, int64_t n2,
              bool fortran) {
    std::string header = "{'descr': '<i2', 'fortran_order': " + std::string(fortran ? "True" : "False") +
                         ", 'shape': (" + std::to_string(n0) + ", " + std::to_string(n1) + ", " +
                         std::to_string(n2) + "), }";
    while ((10 + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::ofstream f(path, std::ios::binary);
    f.write("\x93NUMPY\x01\x00", 8);
    const uint16_t len = uint16_t(header.size());
    f.put(char(len & 0xff)).put(char(len >> 8));
    f.write(header.data(), std::streamsize(header.size()));
    f.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size() * 2));
}

Volume makeVolume(std::array<int64_t, 3> dims, glm::dvec3 spacing) {
    Volume v;
    v.path = "synthetic";
    v.dims = dims;
    v.voxelToWorld = glm::dmat4(1.0);
    v.voxelToWorld[0][0] = spacing.x;
    v.voxelToWorld[1][1] = spacing.y;
    v.voxelToWorld[2][2] = spacing.z;
    v.labels.assign(size_t(dims[0] * dims[1] * dims[2]), 0);
    return v;
}

void ball(Volume& v, glm::dvec3 c, double r, int32_t label) {
    const glm::dvec3 s = v.spacing();
    for (int64_t k = 0; k < v.dims[2]; ++k)
        for (int64_t j = 0; j < v.dims[1]; ++j)
            for (int64_t i = 0; i < v.dims[0]; ++i) {
                const glm::dvec3 d = (glm::dvec3(double(i), double(j), double(k)) - c) * s;
                if (glm::dot(d, d) <= r * r) v.labels[size_t(i + v.dims[0] * (j + v.dims[1] * k))] = label;
            }
}

TEST(MasksLoad, MissingFileNamesIt) {
    Result<Volume> v = loadNifti("/nonexistent/mask.nii.gz");
    ASSERT_FALSE(v.ok());
    EXPECT_EQ(v.error().code, ErrorCode::kBadInput);
    EXPECT_NE(v.error().message.find("/nonexistent/mask.nii.gz"), std::string::npos) << v.error().message;
}

TEST(MasksLoad, NotNiftiNamesIt) {
    const std::string path = tempPath("garbage.nii");
    {
        std::ofstream f(path);
        f << "this is not a NIfTI header";
    }
    Result<Volume> v = loadNifti(path);
    ASSERT_FALSE(v.ok());
    EXPECT_EQ(v.error().code, ErrorCode::kBadInput);
    EXPECT_NE(v.error().message.find(path), std::string::npos) << v.error().message;
    std::remove(path.c_str());
}

TEST(MasksLoad, UnknownExtension) {
    Result<Volume> v = loadVolume("mask.mha");
    ASSERT_FALSE(v.ok());
    EXPECT_NE(v.error().message.find("mask.mha"), std::string::npos);
}

TEST(MasksLoad, AtlasSformAndLabels) {
    Result<Volume> v = loadNifti(kNifti + "/aal.nii.gz");
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_EQ(v->dims, (std::array<int64_t, 3>{181, 217, 181}));
    EXPECT_EQ(v->transform, "sform");
    EXPECT_DOUBLE_EQ(v->voxelToWorld[3][0], -90.0);
    EXPECT_DOUBLE_EQ(v->spacing().x, 1.0);
    EXPECT_EQ(labelsPresent(*v).size(), 116u);
}

// A one-shot comparison's backend (oneShotMaskBackend): the run's points
// are bounded by the nonzero voxels, eight a voxel for DeepMind's surfels,
// summed over the conventions; under auto a bound within 2^18 points a
// thread takes the CPU backend.
TEST(MasksOneShot, TheBoundCountsNonzeroVoxelsAndSurfelCorners) {
    Volume a, b;
    a.dims = b.dims = {64, 64, 64};
    a.labels8.assign(size_t(64 * 64 * 64), 0);
    b.labels8.assign(size_t(64 * 64 * 64), 0);
    std::fill(a.labels8.begin(), a.labels8.begin() + 20000, uint8_t(1));
    std::fill(b.labels8.begin(), b.labels8.begin() + 20000, uint8_t(3));
    EXPECT_EQ(nonzeroVoxels(a), 20000u);
    Volume wide = a;
    wide.labels8.clear();
    wide.labels.assign(size_t(64 * 64 * 64), 0);
    std::fill(wide.labels.begin(), wide.labels.begin() + 7, -2);
    EXPECT_EQ(nonzeroVoxels(wide), 7u);
    Options o;
    o.threads = 1;  // 2^18 = 262144 points
    // 40000 voxels: 40000 points a boundary or foreground convention.
    EXPECT_EQ(oneShotMaskBackend(o, a, b, {Convention::kRthdist}), Backend::kCpu);
    EXPECT_EQ(oneShotMaskBackend(o, a, b, {Convention::kMonai, Convention::kItk}), Backend::kCpu);
    // Surfels: 320000 > 2^18.
    EXPECT_EQ(oneShotMaskBackend(o, a, b, {Convention::kDeepmind}), Backend::kAuto);
    o.threads = 2;
    EXPECT_EQ(oneShotMaskBackend(o, a, b, {Convention::kDeepmind}), Backend::kCpu);
    o.deviceIndex = 0;  // a device named: as asked
    EXPECT_EQ(oneShotMaskBackend(o, a, b, {Convention::kRthdist}), Backend::kAuto);
}

TEST(MasksLoad, GridMismatchNamesBothFiles) {
    Result<Volume> a = loadNifti(kNifti + "/HarvardOxford-cort-maxprob-thr0-1mm.nii.gz");
    Result<Volume> b = loadNifti(kNifti + "/JHU-WhiteMatter-labels-1mm.nii.gz");
    ASSERT_TRUE(a.ok() && b.ok());
    std::optional<Error> e = checkSameGrid(*a, *b);
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->code, ErrorCode::kBadInput);
    EXPECT_NE(e->message.find("HarvardOxford"), std::string::npos) << e->message;
    EXPECT_NE(e->message.find("JHU"), std::string::npos) << e->message;
    EXPECT_FALSE(checkSameGrid(*a, *a).has_value());
}

TEST(MasksLoad, NpyCAndFortranOrder) {
    const int64_t n0 = 3, n1 = 4, n2 = 5;
    std::vector<int16_t> c(size_t(n0 * n1 * n2)), f(c.size());
    for (int64_t i = 0; i < n0; ++i)
        for (int64_t j = 0; j < n1; ++j)
            for (int64_t k = 0; k < n2; ++k) {
                const int16_t value = int16_t(100 * i + 10 * j + k);
                c[size_t((i * n1 + j) * n2 + k)] = value;
                f[size_t(i + n0 * (j + n1 * k))] = value;
            }
    for (bool fortran : {false, true}) {
        const std::string path = tempPath(fortran ? "f.npy" : "c.npy");
        writeNpy(path, fortran ? f : c, n0, n1, n2, fortran);
        Result<Volume> v = loadNpy(path, glm::dvec3(0.5, 0.7, 3.0));
        ASSERT_TRUE(v.ok()) << v.error().message;
        EXPECT_EQ(v->dims, (std::array<int64_t, 3>{n0, n1, n2}));
        EXPECT_EQ(v->labels[size_t(2 + n0 * (3 + n1 * 4))], 234) << "fortran " << fortran;
        EXPECT_DOUBLE_EQ(v->spacing().z, 3.0);
        std::remove(path.c_str());
    }
}

// The host extraction (packed rows, row_bits.hpp) against a voxel-by-voxel
// brute force: rows shorter than a word, of whole words and across words,
// 8- and 32-bit labels, a label value, any non-zero, a value the 8-bit type
// cannot hold, every connectivity.
TEST(MasksBoundary, MatchesBruteForce) {
    std::mt19937 rng(13);
    for (const detail::Dims dims :
         {detail::Dims{9, 8, 7}, detail::Dims{64, 5, 4}, detail::Dims{130, 6, 5}, detail::Dims{70, 1, 3}}) {
        for (bool eightBit : {false, true}) {
            Volume v = makeVolume(dims, glm::dvec3(1.0));
            for (auto& l : v.labels) l = (rng() % 100) < 60 ? 3 : int32_t(rng() % 3);
            if (eightBit) {
                v.labels8.assign(v.labels.begin(), v.labels.end());
                v.labels.clear();
            }
            for (LabelSelect select :
                 {LabelSelect{3, false}, LabelSelect{1, true}, LabelSelect{259, false}}) {
                std::vector<uint8_t> mask(size_t(v.voxelCount()));
                for (size_t i = 0; i < mask.size(); ++i) {
                    const int32_t l = eightBit ? int32_t(v.labels8[i]) : v.labels[i];
                    mask[i] = select.anyNonZero ? l != 0 : l == select.value;
                }
                for (int conn : {6, 18, 26}) {
                    const detail::Extraction e = detail::extractBoundary(v, select, conn, 2);
                    const std::string what =
                        "dims " + std::to_string(dims[0]) + " 8-bit " + std::to_string(eightBit) + " label " +
                        std::to_string(select.value) + " connectivity " + std::to_string(conn);
                    EXPECT_EQ(e.count, uint64_t(std::count(mask.begin(), mask.end(), 1))) << what;
                    std::vector<uint64_t> want;
                    for (int64_t k = 0; k < dims[2]; ++k)
                        for (int64_t j = 0; j < dims[1]; ++j)
                            for (int64_t i = 0; i < dims[0]; ++i) {
                                const size_t at = size_t(i + dims[0] * (j + dims[1] * k));
                                if (!mask[at]) continue;
                                bool edge = false;
                                for (int dz = -1; dz <= 1; ++dz)
                                    for (int dy = -1; dy <= 1; ++dy)
                                        for (int dx = -1; dx <= 1; ++dx) {
                                            const int l1 = std::abs(dx) + std::abs(dy) + std::abs(dz);
                                            if (l1 == 0 || l1 > (conn == 6 ? 1 : conn == 18 ? 2 : 3))
                                                continue;
                                            const int64_t x = i + dx, y = j + dy, z = k + dz;
                                            if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] ||
                                                z >= dims[2] ||
                                                !mask[size_t(x + dims[0] * (y + dims[1] * z))])
                                                edge = true;
                                        }
                                if (edge) want.push_back(at);
                            }
                    EXPECT_EQ(std::vector<uint64_t>(e.boundary.begin(), e.boundary.end()), want) << what;
                }
            }
        }
    }
}

// The compute pass (masks_gpu, on lavapipe here) finds the host extraction's
// voxels, in its order: 8- and 32-bit labels, a label value, any non-zero,
// every connectivity, labels confined to a few rows and slices (the pass
// sees only their box), touching the volume's faces, or absent.
TEST(MasksBoundary, DevicePassEqualsHost) {
    auto pass = masks_gpu::BoundaryPass::create(-1, true);
    ASSERT_TRUE(pass.has_value()) << pass.error().message;
    std::mt19937 rng(29);
    struct Case {
        detail::Dims dims;
        std::array<int64_t, 6> region;  // x0, x1, y0, y1, z0, z1 (inclusive) holding labels
        bool eightBit;
    };
    const std::vector<Case> cases{
        {{9, 8, 7}, {0, 8, 0, 7, 0, 6}, false},     // labels everywhere, faces touched
        {{33, 17, 12}, {4, 20, 3, 9, 2, 5}, true},  // a box inside; 33 x 17: rows across words
        {{1, 5, 6}, {0, 0, 1, 3, 0, 5}, true},      // one voxel wide
        {{40, 3, 2}, {0, 39, 2, 2, 1, 1}, false},   // one row
        {{16, 16, 16}, {0, 0, 0, 0, 0, 0}, true},   // labels in voxel 0 only
    };
    for (const Case& c : cases) {
        Volume v = makeVolume(c.dims, glm::dvec3(1.0));
        for (int64_t k = c.region[4]; k <= c.region[5]; ++k)
            for (int64_t j = c.region[2]; j <= c.region[3]; ++j)
                for (int64_t i = c.region[0]; i <= c.region[1]; ++i)
                    v.labels[size_t(i + c.dims[0] * (j + c.dims[1] * k))] = int32_t(rng() % 4);
        if (c.eightBit) {
            v.labels8.assign(v.labels.begin(), v.labels.end());
            v.labels.clear();
        }
        for (LabelSelect select :
             {LabelSelect{2, false}, LabelSelect{1, true}, LabelSelect{7, false}, LabelSelect{258, false}}) {
            for (int conn : {6, 18, 26}) {
                const detail::Extraction host = detail::extractBoundary(v, select, conn, 2);
                Result<detail::Extraction> device =
                    detail::extractBoundaryOnDevice(**pass, v, select, conn, 2);
                ASSERT_TRUE(device.has_value()) << device.error().message;
                const std::string what =
                    "dims " + std::to_string(c.dims[0]) + "x" + std::to_string(c.dims[1]) + "x" +
                    std::to_string(c.dims[2]) + " label " + std::to_string(select.value) +
                    (select.anyNonZero ? " (any)" : "") + " connectivity " + std::to_string(conn);
                EXPECT_EQ(device->count, host.count) << what;
                EXPECT_EQ(device->boundary, host.boundary) << what;
            }
        }
    }
    EXPECT_EQ((*pass)->validationMessageCount(), 0u);
}

// Several masks in one submission of the pass (8- and 32-bit labels, boxes
// of different sizes, a mask with nothing selected in between): each equals
// its own host extraction.
TEST(MasksBoundary, DevicePassTakesSeveralMasks) {
    auto pass = masks_gpu::BoundaryPass::create(-1, true);
    ASSERT_TRUE(pass.has_value()) << pass.error().message;
    std::mt19937 rng(31);
    Volume a = makeVolume({20, 11, 9}, glm::dvec3(1.0));
    Volume b = makeVolume({7, 30, 5}, glm::dvec3(1.0));
    for (auto& l : a.labels) l = int32_t(rng() % 3);
    for (size_t i = 0; i < b.labels.size(); i += 2) b.labels[i] = int32_t(rng() % 2);
    b.labels8.assign(b.labels.begin(), b.labels.end());
    b.labels.clear();
    const std::array<detail::MaskRef, 3> masks{detail::MaskRef{&a, LabelSelect{2, false}},
                                               detail::MaskRef{&b, LabelSelect{9, false}},
                                               detail::MaskRef{&b, LabelSelect{1, true}}};
    for (int conn : {6, 26}) {
        Result<std::vector<detail::Extraction>> device =
            detail::extractBoundariesOnDevice(**pass, masks, conn, 2);
        ASSERT_TRUE(device.has_value()) << device.error().message;
        ASSERT_EQ(device->size(), masks.size());
        for (size_t k = 0; k < masks.size(); ++k) {
            const detail::Extraction host =
                detail::extractBoundary(*masks[k].volume, masks[k].select, conn, 2);
            EXPECT_EQ((*device)[k].count, host.count) << "mask " << k << " connectivity " << conn;
            EXPECT_EQ((*device)[k].boundary, host.boundary) << "mask " << k << " connectivity " << conn;
        }
        EXPECT_EQ((*device)[1].count, 0u);
    }
    EXPECT_EQ((*pass)->validationMessageCount(), 0u);
}

TEST(MasksCompare, InvalidOptions) {
    Options o;
    o.backend = Backend::kCpu;
    Result<MaskEngine> engine = makeMaskEngine(o);
    ASSERT_TRUE(engine.ok());
    Volume v = makeVolume({6, 6, 6}, glm::dvec3(1.0));
    ball(v, glm::dvec3(3.0), 2.0, 1);
    MaskOptions mo;
    mo.connectivity = 7;
    EXPECT_EQ(compareMasks(*engine, v, {}, v, {}, mo).error().code, ErrorCode::kInvalidArgument);
    mo.connectivity = 0;
    mo.percentiles = {101.0};
    EXPECT_EQ(compareMasks(*engine, v, {}, v, {}, mo).error().code, ErrorCode::kInvalidArgument);
}

// Every convention on the backend under test equals the CPU backend's
// values, with the host's extraction (the default) and with the compute pass.
TEST(MasksBackend, AllConventionsMatchCpu) {
    for (bool devicePass : {false, true}) {
        Options o;
        o.backend = backendUnderTest();
        Result<MaskEngine> engine = makeMaskEngine(o, devicePass);
        ASSERT_TRUE(engine.ok()) << engine.error().message;
        Options oc;
        oc.backend = Backend::kCpu;
        Result<MaskEngine> cpu = makeMaskEngine(oc);
        ASSERT_TRUE(cpu.ok());
        Volume a = makeVolume({30, 28, 10}, glm::dvec3(0.5, 0.7, 3.0));
        Volume b = a;
        ball(a, glm::dvec3(14, 13, 5), 6.0, 1);
        ball(b, glm::dvec3(16, 12, 4.5), 7.0, 1);
        a.labels[size_t(1 + 30 * (1 + 28 * 1))] = 1;  // an outlier voxel
        const double diag = glm::length(glm::dvec3(29 * 0.5, 27 * 0.7, 9 * 3.0));
        for (Convention c : kAllConventions) {
            MaskOptions mo;
            mo.convention = c;
            mo.percentiles = {95.0, 50.0};
            Result<MaskResult> r = compareMasks(*engine, a, {}, b, {}, mo);
            Result<MaskResult> w = compareMasks(*cpu, a, {}, b, {}, mo);
            ASSERT_TRUE(r.ok() && w.ok()) << conventionName(c);
            EXPECT_NEAR(r->hd, w->hd, 1e-6 * diag) << conventionName(c);
            EXPECT_NEAR(r->msd, w->msd, 1e-6 * diag) << conventionName(c);
            ASSERT_EQ(r->hdPercentile.size(), w->hdPercentile.size());
            for (size_t i = 0; i < r->hdPercentile.size(); ++i)
                EXPECT_NEAR(r->hdPercentile[i], w->hdPercentile[i], 1e-6 * diag) << conventionName(c);
            EXPECT_EQ(r->aToB.points, w->aToB.points);
            EXPECT_GT(r->hd, 6.0);  // the outlier voxel (about 8 mm from b)
            // A GPU backend with the pass finds boundary voxels with it (not
            // deepmind's surfels); the CPU backend on the host.
            const bool onDevice = devicePass && o.backend != Backend::kCpu && c != Convention::kDeepmind;
            EXPECT_EQ(r->extraction, onDevice ? "device" : "host") << conventionName(c);
            EXPECT_EQ(w->extraction, "host") << conventionName(c);
        }
    }
}

TEST(MasksBackend, EmptyMasksHaveAStatus) {
    Options o;
    o.backend = backendUnderTest();
    Result<MaskEngine> engine = makeMaskEngine(o);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    Volume empty = makeVolume({8, 8, 8}, glm::dvec3(1.0));
    Volume full = empty;
    ball(full, glm::dvec3(4.0), 2.5, 1);
    MaskOptions mo;
    mo.convention = Convention::kMonai;
    Result<MaskResult> both = compareMasks(*engine, empty, {}, empty, {}, mo);
    ASSERT_TRUE(both.ok());
    EXPECT_EQ(both->empty, EmptyStatus::kBothEmpty);
    EXPECT_EQ(both->emptyValues.hd, "nan");
    Result<MaskResult> one = compareMasks(*engine, full, {}, empty, {}, mo);
    ASSERT_TRUE(one.ok());
    EXPECT_EQ(one->empty, EmptyStatus::kBEmpty);
    EXPECT_EQ(one->emptyValues.hd, "inf");
    EXPECT_TRUE(std::isnan(one->hd));  // never a number folded into a mean
    // One voxel each: HD is their distance.
    Volume v1 = empty, v2 = empty;
    v1.labels[0] = 1;
    v2.labels[size_t(3 + 8 * (4 + 8 * 5))] = 1;
    mo.convention = Convention::kRthdist;
    Result<MaskResult> r = compareMasks(*engine, v1, {}, v2, {}, mo);
    ASSERT_TRUE(r.ok());
    EXPECT_NEAR(r->hd, std::sqrt(9.0 + 16.0 + 25.0), 1e-9);
    EXPECT_EQ(r->aToB.nearestVoxel, (std::array<int64_t, 3>{3, 4, 5}));
}

}  // namespace
}  // namespace rthdist::masks
