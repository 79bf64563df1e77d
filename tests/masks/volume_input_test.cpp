// The volume readers of rthdist-masks against hostile and malformed files
// (issue 36): NIfTI headers validated before use (dim[0] outside 1..7,
// NaN/zero/negative/infinite pixdim, NaN voxels, NaN origins, spacings
// below what the engine computes exactly), the inflated-size cap, .npy
// headers read as NumPy's format specification says, and regular files
// only (a FIFO or /dev/zero is refused without reading or blocking). Each
// refusal is kBadInput naming the file and the field.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "rthdist/masks.hpp"
#include "volume_files.hpp"

namespace rthdist::masks {
namespace {

using namespace rthdist::masks_test;

std::string tempPath(const std::string& name) {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir ? dir : "/tmp") + "/rthdist_volume_input_" + std::to_string(::getpid()) + "_" +
           name;
}

void expectRefused(const Result<Volume>& v, const std::string& path, const std::vector<std::string>& words) {
    ASSERT_FALSE(v.ok()) << "accepted " << path;
    EXPECT_EQ(v.error().code, ErrorCode::kBadInput) << v.error().message;
    EXPECT_NE(v.error().message.find(path), std::string::npos) << v.error().message;
    for (const std::string& w : words)
        EXPECT_NE(v.error().message.find(w), std::string::npos) << v.error().message;
}

TEST(NiftiHeader, Dim0OutsideOneToSevenIsRefusedNotACrash) {
    // libnifti2 3.0.1 smashed its stack on dim[0] > 7 and read 0, -1 or 8 as another grid.
    for (int64_t dim0 : std::vector<int64_t>{0, -1, 8, 9, 100, 32767, -32768, int64_t(1) << 40}) {
        const std::string path = tempPath("dim0.nii");
        writeFile(path, nifti2(dim0, 4, 4, 4));
        expectRefused(loadNifti(path), path, {"dim[0] = " + std::to_string(dim0), "1..7"});
        std::remove(path.c_str());
    }
    const std::string path = tempPath("dim0ok.nii");
    writeFile(path, nifti2(3, 4, 4, 4));
    const Result<Volume> v = loadNifti(path);
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_EQ(v->dims, (std::array<int64_t, 3>{4, 4, 4}));
    std::remove(path.c_str());
}

TEST(NiftiHeader, NonPositiveDimIsRefused) {
    for (int16_t bad : std::vector<int16_t>{0, -1, -32768}) {
        Nifti1 n(4, 4, 4, 2, 1);
        n.dim(2, bad);
        const std::string path = tempPath("dim2.nii");
        writeFile(path, n.bytes());
        expectRefused(loadNifti(path), path, {"dim[2] = " + std::to_string(bad)});
        std::remove(path.c_str());
    }
}

TEST(NiftiHeader, BadPixdimIsRefusedNotOneMillimetre) {
    // libnifti turned NaN, zero, negative or infinite pixdim into 1 mm.
    for (float bad : {std::nanf(""), 0.0f, -1.5f, std::numeric_limits<float>::infinity()}) {
        for (int d = 1; d <= 3; ++d) {
            Nifti1 n(4, 4, 4, 2, 1);
            n.pixdim(d, bad);
            const std::string path = tempPath("pixdim.nii.gz");
            writeGz(path, n.bytes());
            expectRefused(loadNifti(path), path, {"pixdim[" + std::to_string(d) + "]", "positive finite"});
            std::remove(path.c_str());
        }
    }
}

TEST(NiftiHeader, SpacingBelowTheLimitIsRefusedWithTheLimitNamed) {
    for (float tiny : {1e-45f, 1e-40f, 1e-31f}) {
        Nifti1 n(4, 4, 4, 2, 1);
        n.pixdim(1, tiny);
        const std::string path = tempPath("tiny.nii");
        writeFile(path, n.bytes());
        expectRefused(loadNifti(path), path, {"pixdim", "1e-30"});
        std::remove(path.c_str());
    }
    Nifti1 n(4, 4, 4, 2, 1);
    n.pixdim(1, 2e-30f);
    const std::string path = tempPath("small.nii");
    writeFile(path, n.bytes());
    const Result<Volume> v = loadNifti(path);
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_DOUBLE_EQ(v->spacing().x, double(2e-30f));
    std::remove(path.c_str());
}

TEST(NiftiHeader, NanOriginIsRefused) {
    const float rows[12] = {1, 0, 0, std::nanf(""), 0, 1, 0, 0, 0, 0, 1, 0};
    Nifti1 n(4, 4, 4, 2, 1);
    n.sform(rows);
    const std::string path = tempPath("nanorigin.nii");
    writeFile(path, n.bytes());
    expectRefused(loadNifti(path), path, {"srow_x[3]", "not finite"});
    std::remove(path.c_str());
    // The qform's origin.
    Nifti1 q(4, 4, 4, 2, 1);
    put<int16_t>(q.header, 252, 1);
    put<float>(q.header, 272, std::nanf(""));
    writeFile(path, q.bytes());
    expectRefused(loadNifti(path), path, {"qoffset_y", "not finite"});
    std::remove(path.c_str());
}

TEST(NiftiHeader, NanFloatVoxelIsRefusedNotZero) {
    Nifti1 n(3, 3, 3, 16, 4);  // float32
    const float one = 1.0f, nan = std::nanf("");
    std::memcpy(n.voxels.data(), &one, 4);
    std::memcpy(n.voxels.data() + 4 * 13, &nan, 4);
    const std::string path = tempPath("nanvoxel.nii");
    writeFile(path, n.bytes());
    expectRefused(loadNifti(path), path, {"nan", "voxel index 13"});
    std::remove(path.c_str());
}

TEST(NiftiHeader, InflatedSizeIsCappedBeforeReading) {
    // 64 x 64 x 64 int16: 512 KiB in the file, 1 MiB held as int32; the .gz is a few hundred bytes.
    Nifti1 n(64, 64, 64, 4, 2);
    const std::string path = tempPath("bomb.nii.gz");
    writeGz(path, n.bytes());
    VolumeLimits small;
    small.maxVolumeBytes = 1 << 19;
    expectRefused(loadNifti(path, small), path,
                  {"262144 voxels", "1048576 held", "volume limit of 524288 bytes", "--max-volume-mib"});
    VolumeLimits enough;
    enough.maxVolumeBytes = 1 << 20;
    const Result<Volume> v = loadNifti(path, enough);
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_EQ(v->labels.size(), size_t(64 * 64 * 64));
    EXPECT_EQ(v->labels[0], 1);
    EXPECT_TRUE(v->labels8.empty());
    // The default.
    EXPECT_EQ(VolumeLimits{}.maxVolumeBytes, uint64_t(2) << 30);
    std::remove(path.c_str());
}

TEST(NiftiHeader, GzipStreamShorterThanTheHeaderSaysIsRefused) {
    Nifti1 n(16, 16, 16, 2, 1);
    const std::string path = tempPath("short.nii.gz");
    writeGz(path, n.bytes().substr(0, 352 + 1000));
    expectRefused(loadNifti(path), path, {"truncated"});
    std::remove(path.c_str());
}

// One gzip member of `bytes` (zlib, level 6).
std::string gzipped(const std::string& bytes) {
    z_stream zs{};
    EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&zs, uLong(bytes.size())), '\0');
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    zs.avail_in = uInt(bytes.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = uInt(out.size());
    EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    return out;
}

Result<Volume> loadNiftiBytes(const std::string& path, const std::string& bytes) {
    writeFile(path, bytes);
    Result<Volume> v = loadNifti(path);
    std::remove(path.c_str());
    return v;
}

TEST(NiftiHeader, GzipStreamIsReadToItsVerifiedEnd) {
    // The reader stopped at the last voxel: a missing or corrupt trailer
    // (CRC32, ISIZE) and anything after the voxels went unnoticed.
    Nifti1 n(9, 8, 7, 2, 1);
    const std::string gz = gzipped(n.bytes());
    const std::string path = tempPath("stream.nii.gz");
    for (size_t cut : {4, 8}) {
        SCOPED_TRACE(cut);
        expectRefused(loadNiftiBytes(path, gz.substr(0, gz.size() - cut)), path, {"truncated gzip stream"});
    }
    std::string badCrc = gz;
    badCrc[badCrc.size() - 8] ^= 1;
    expectRefused(loadNiftiBytes(path, badCrc), path, {"corrupt gzip stream", "incorrect data check"});
    expectRefused(loadNiftiBytes(path, gz + "garbage"), path, {"corrupt gzip stream", "byte offset"});
    // Inflated bytes after the voxels, in the same member or a second one:
    // refused after inflating one byte of them (a bomb is not inflated).
    const std::string more = "after the last voxel (vox_offset 352 + 504 bytes)";
    expectRefused(loadNiftiBytes(path, gzipped(n.bytes() + std::string(1 << 20, '\0'))), path, {more});
    expectRefused(loadNiftiBytes(path, gz + gzipped("x")), path, {more});
    // Legal gzip: the voxels over two members, an empty member, zero padding.
    const std::string bytes = n.bytes();
    const Result<Volume> split =
        loadNiftiBytes(path, gzipped(bytes.substr(0, 400)) + gzipped(bytes.substr(400)) + gzipped("") +
                                 std::string(100, '\0'));
    ASSERT_TRUE(split.ok()) << split.error().message;
    EXPECT_EQ(split->labels8.size(), size_t(9 * 8 * 7));
    EXPECT_EQ(split->labels8[0], 1);
    // A plain .nii is read as before: bytes after the voxels are not read.
    const std::string plain = tempPath("plain.nii");
    const Result<Volume> padded = loadNiftiBytes(plain, bytes + "tail");
    ASSERT_TRUE(padded.ok()) << padded.error().message;
}

TEST(NiftiHeader, BigEndianFileReadsAsLittle) {
    Nifti1 n(3, 2, 2, 4, 2);  // int16
    auto swapAll = [](std::string& b, size_t at, size_t count, size_t width) {
        for (size_t i = 0; i < count; ++i)
            std::reverse(b.begin() + long(at + i * width), b.begin() + long(at + (i + 1) * width));
    };
    n.voxels.assign(24, '\0');
    n.voxels[1] = 7;  // big-endian 7 at voxel 0
    n.voxels[5] = 2;  // voxel 2
    std::string h = n.header;
    swapAll(h, 0, 1, 4);
    swapAll(h, 40, 8, 2);
    swapAll(h, 70, 2, 2);
    swapAll(h, 76, 8, 4);
    swapAll(h, 108, 1, 4);
    const std::string path = tempPath("be.nii");
    writeFile(path, h + n.voxels);
    const Result<Volume> v = loadNifti(path);
    ASSERT_TRUE(v.ok()) << v.error().message;
    EXPECT_EQ(v->labels[0], 7);
    EXPECT_EQ(v->labels[2], 2);
    std::remove(path.c_str());
}

// ---- .npy ----

Result<Volume> loadNpyBytes(const std::string& path, const std::string& bytes) {
    writeFile(path, bytes);
    Result<Volume> v = loadNpy(path, glm::dvec3(1.0));
    std::remove(path.c_str());
    return v;
}

TEST(NpyHeader, ShapeProductOverflowIsRefusedNotWrapped) {
    // 2^32 * 2^32 * 2 wraps to 0 in 64 bits (and 2^62 * 4 * 1 to 0: the byte count).
    const std::string path = tempPath("overflow.npy");
    expectRefused(loadNpyBytes(path, npy("{'descr': '|u1', 'fortran_order': False, 'shape': (4294967296, "
                                         "4294967296, 2), }",
                                         std::string(8, '\1'))),
                  path, {"shape", "overflows 64 bits"});
    expectRefused(loadNpyBytes(path, npy("{'descr': '<i4', 'fortran_order': False, 'shape': "
                                         "(4611686018427387904, 1, 1), }",
                                         std::string(8, '\1'))),
                  path, {"shape", "overflows 64 bits"});
}

TEST(NpyHeader, ShapeBeyondTheFileIsRefused) {
    const std::string path = tempPath("short.npy");
    expectRefused(loadNpyBytes(path, npy("{'descr': '<i2', 'fortran_order': False, 'shape': (4, 4, 4), }",
                                         std::string(127, '\0'))),
                  path, {"truncated", "needs 128 bytes", "127"});
}

TEST(NpyHeader, MalformedNumbersNameTheFieldNotStoll) {
    const std::string path = tempPath("numbers.npy");
    for (const auto& [shape, words] : std::vector<std::pair<std::string, std::vector<std::string>>>{
             {"(99999999999999999999, 1, 1)", {"shape[0]", "exceeds 2^63 - 1"}},
             {"(1, x, 1)", {"shape[1]", "integer expected"}},
             {"(1, 1, -3)", {"shape[2]", "negative"}},
             {"(1, 1, 0)", {"shape[2] is 0"}},
             {"(4)", {"not a tuple"}},
             {"(1, 1)", {"2 axes"}},
             {"(1, 1, 1", {"shape"}},
             {"(1, 1, 1.5)", {"shape[2]", "not a decimal integer"}},
             {"(01, 1, 1)", {"shape[0]", "leading zeros"}},
         }) {
        const Result<Volume> v = loadNpyBytes(
            path,
            npy("{'descr': '|u1', 'fortran_order': False, 'shape': " + shape + ", }", std::string(64, '\0')));
        expectRefused(v, path, words);
        if (!v) EXPECT_EQ(v.error().message.find("stoll"), std::string::npos) << v.error().message;
    }
}

TEST(NpyHeader, DictIsReadAsNumPyReadsIt) {
    const std::string path = tempPath("dict.npy");
    const std::string data(8, '\1');
    // A 'shape' inside a string value is not the shape (the old reader took the first "'shape'").
    expectRefused(
        loadNpyBytes(path, npy("{'descr': '|u1', 'note': \"'shape': (1, 1, 1)\", 'fortran_order': False, "
                               "'shape': (2, 2, 2), }",
                               data)),
        path, {"key 'note'"});
    expectRefused(
        loadNpyBytes(path, npy("{'descr': \"'shape': (1, 1, 1)\", 'fortran_order': False, 'shape': (2, 2, "
                               "2), }",
                               data)),
        path, {"descr", "not a label type"});
    // Duplicate keys.
    expectRefused(
        loadNpyBytes(path, npy("{'descr': '|u1', 'fortran_order': False, 'shape': (1, 1, 1), 'shape': "
                               "(2, 2, 2), }",
                               data)),
        path, {"'shape' appears twice"});
    expectRefused(
        loadNpyBytes(path, npy("{'descr': '<i8', 'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, "
                               "2)}",
                               data)),
        path, {"'descr' appears twice"});
    // fortran_order other than True/False.
    for (const std::string& order : {"'NotTrue'", "1", "Truely", "'True'", "None"})
        expectRefused(
            loadNpyBytes(path,
                         npy("{'descr': '|u1', 'fortran_order': " + order + ", 'shape': (2, 2, 2)}", data)),
            path, {"fortran_order must be True or False"});
    // A missing key, text after the dict, not a dict.
    expectRefused(loadNpyBytes(path, npy("{'descr': '|u1', 'shape': (2, 2, 2)}", data)), path,
                  {"'fortran_order' is missing"});
    expectRefused(
        loadNpyBytes(path, npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, 2)} x", data)), path,
        {"text after the dict"});
    expectRefused(loadNpyBytes(path, npy("['descr', '|u1']", data)), path, {"not a dict literal"});
    // Versions: 1.0, 2.0 and 3.0 only.
    std::string v4 = npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, 2)}", data, 2);
    v4[6] = 4;
    expectRefused(loadNpyBytes(path, v4), path, {"version 4.0"});
    std::string v11 = npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, 2)}", data);
    v11[7] = 1;
    expectRefused(loadNpyBytes(path, v11), path, {"version 1.1"});
}

TEST(NpyHeader, EveryVersionAndByteOrderReads) {
    const std::string path = tempPath("ok.npy");
    // (2, 1, 3) big-endian int16 in C order: (i, 0, k) = 10 i + k.
    std::string data;
    for (int i = 0; i < 2; ++i)
        for (int k = 0; k < 3; ++k) {
            data += '\0';
            data += char(10 * i + k);
        }
    for (int major : {1, 2, 3}) {
        const Result<Volume> v = loadNpyBytes(
            path, npy("{\"descr\": '>i2', \"fortran_order\": False, \"shape\": (2, 1, 3,)}", data, major));
        ASSERT_TRUE(v.ok()) << v.error().message;
        EXPECT_EQ(v->dims, (std::array<int64_t, 3>{2, 1, 3}));
        for (int i = 0; i < 2; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_EQ(v->labels[size_t(i + 2 * k)], 10 * i + k) << major;
    }
}

TEST(NpyFile, DevZeroIsRefusedWithoutReading) {
    Result<Volume> v = loadNpy("/dev/zero", glm::dvec3(1.0));
    expectRefused(v, "/dev/zero", {"character device", "not a regular file"});
    v = loadVolume("/dev/null.npy");  // missing: named
    ASSERT_FALSE(v.ok());
}

TEST(NpyFile, FifoIsRefusedWithoutBlocking) {
    // Nobody writes to the FIFO: reading (or a blocking open) would wait forever.
    for (const char* name : {"pipe.npy", "pipe.nii"}) {
        const std::string path = tempPath(name);
        ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
        expectRefused(loadVolume(path), path, {"FIFO", "not a regular file"});
        std::remove(path.c_str());
    }
}

TEST(NpyFile, DirectoryIsRefused) {
    const char* dir = std::getenv("TMPDIR");
    const std::string path = std::string(dir ? dir : "/tmp");
    expectRefused(loadNpy(path, glm::dvec3(1.0)), path, {"directory"});
}

TEST(NpyFile, VolumeCapAppliesToNpy) {
    const std::string path = tempPath("cap.npy");
    writeFile(path,
              npy("{'descr': '<i2', 'fortran_order': True, 'shape': (8, 8, 8)}", std::string(1024, '\0')));
    VolumeLimits limits;
    limits.maxVolumeBytes = 1024;  // 512 voxels held as int32: 2048 bytes
    expectRefused(loadNpy(path, glm::dvec3(1.0), std::nullopt, limits), path, {"volume limit of 1024 bytes"});
    limits.maxVolumeBytes = 2048;
    EXPECT_TRUE(loadNpy(path, glm::dvec3(1.0), std::nullopt, limits).ok());
    std::remove(path.c_str());
}

TEST(NpyFile, SpacingBelowTheLimitIsRefused) {
    const std::string path = tempPath("spacing.npy");
    writeFile(path,
              npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, 2)}", std::string(8, '\1')));
    expectRefused(loadNpy(path, glm::dvec3(1.0, 1e-40, 1.0)), path, {"spacing", "1e-30"});
    expectRefused(loadNpy(path, glm::dvec3(1.0, 1.0, 1e31)), path, {"spacing", "1e+30"});
    EXPECT_TRUE(loadNpy(path, glm::dvec3(1.0, 1e-29, 1.0)).ok());
    std::remove(path.c_str());
}

TEST(NpyFile, LargeArraysReadInPiecesInEveryOrder) {
    // Pieces of 4 M voxels: (3, 1024, 2048) C order takes two planes a
    // piece, (1, 2049, 2048) C order scatters rows of one plane larger than
    // a piece, Fortran order is read straight in; uint8 and int16.
    auto value = [](int64_t i, int64_t j, int64_t k) { return int((i * 7 + j * 3 + k) % 251); };
    for (const std::array<int64_t, 3> dims :
         {std::array<int64_t, 3>{3, 1024, 2048}, std::array<int64_t, 3>{1, 2049, 2048}}) {
        for (bool fortran : {false, true}) {
            for (int bytes : {1, 2}) {
                const int64_t n = dims[0] * dims[1] * dims[2];
                std::string data(size_t(n * bytes), '\0');
                for (int64_t i = 0; i < dims[0]; ++i)
                    for (int64_t j = 0; j < dims[1]; ++j)
                        for (int64_t k = 0; k < dims[2]; ++k) {
                            const int64_t at =
                                fortran ? i + dims[0] * (j + dims[1] * k) : (i * dims[1] + j) * dims[2] + k;
                            data[size_t(at * bytes)] = char(value(i, j, k));
                        }
                const std::string path = tempPath("large.npy");
                const std::string dict = std::string("{'descr': '") + (bytes == 1 ? "|u1" : "<i2") +
                                         "', 'fortran_order': " + (fortran ? "True" : "False") +
                                         ", 'shape': (" + std::to_string(dims[0]) + ", " +
                                         std::to_string(dims[1]) + ", " + std::to_string(dims[2]) + "), }";
                const Result<Volume> v = loadNpyBytes(path, npy(dict, data));
                ASSERT_TRUE(v.ok()) << v.error().message;
                int64_t wrong = 0;
                for (int64_t k = 0; k < dims[2]; ++k)
                    for (int64_t j = 0; j < dims[1]; ++j)
                        for (int64_t i = 0; i < dims[0]; ++i) {
                            const size_t at = size_t(i + dims[0] * (j + dims[1] * k));
                            const int got = bytes == 1 ? int(v->labels8[at]) : v->labels[at];
                            wrong += got != value(i, j, k);
                        }
                EXPECT_EQ(wrong, 0) << dict;
            }
        }
    }
}

// ---- volumes built by hand (the C++ API) ----

TEST(VolumeChecks, NanOriginIsRefusedByPrepareAndCompare) {
    Volume v;
    v.path = "by-hand";
    v.dims = {2, 2, 2};
    v.labels8.assign(8, 1);
    v.voxelToWorld[3][1] = std::nan("");
    Options o;
    o.backend = Backend::kCpu;
    Result<MaskEngine> engine = makeMaskEngine(o);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    const Result<PreparedReference> p = prepareReference(*engine, v, LabelSelect{}, MaskOptions{});
    ASSERT_FALSE(p.ok());
    EXPECT_EQ(p.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(p.error().message.find("NaN or infinite origin"), std::string::npos) << p.error().message;
    const Result<MaskResult> r = compareMasks(*engine, v, LabelSelect{}, v, LabelSelect{}, MaskOptions{});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("by-hand"), std::string::npos) << r.error().message;
}

TEST(VolumeChecks, ArraySpacingBelowTheLimitIsRefused) {
    const uint8_t labels[8] = {1, 0, 0, 0, 0, 0, 0, 1};
    LabelArray a;
    a.data = labels;
    a.dims = {2, 2, 2};
    a.kind = "u1";
    glm::dmat4 m(1.0);
    m[2][2] = 1e-45;
    const Result<Volume> v = volumeFromArray(a, m, "array");
    ASSERT_FALSE(v.ok());
    EXPECT_EQ(v.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(v.error().message.find("1e-30"), std::string::npos) << v.error().message;
}

}  // namespace
}  // namespace rthdist::masks
