// The LAS reader (issue 10) on files the tests write: every point data format
// in every version that defines it, scale and offset in double, VLRs skipped,
// the classification filter, and every lie a header can tell refused with
// kBadInput naming the file and the place, before anything is allocated.
#include <cmath>
#include <limits>

#include "las_test_support.hpp"

namespace rthdist::io::test {
namespace {

class LasReader : public TempDirTest {};

// The formats each version defines (1.0/1.1: 0-1, 1.2: 0-3, 1.3: 0-5, 1.4: 0-10).
int lastFormatOf(int minor) {
    constexpr int kLast[5] = {1, 1, 3, 5, 10};
    return kLast[minor];
}

std::vector<LasPoint> samplePoints() {
    return {{{0, 0, 0}, 2},
            {{1, -1, 123456}, 6},
            {{2147483647, -2147483647 - 1, -5}, 2},
            {{-31250, 500, 999}, 9}};
}

TEST_F(LasReader, EveryFormatOfEveryVersion) {
    for (int minor = 0; minor <= 4; ++minor) {
        for (int format = 0; format <= lastFormatOf(minor); ++format) {
            SCOPED_TRACE("LAS 1." + std::to_string(minor) + " format " + std::to_string(format));
            LasSpec s;
            s.minor = minor;
            s.format = format;
            s.scale = {0.01, 0.001, 0.0001};
            s.offset = {512000.0, 5400000.0, -100.0};
            s.points = samplePoints();
            s.vlrs = minor % 3;     // 0, 1 or 2 records to skip
            s.extraBytes = format;  // records longer than the format's minimum
            const std::string path = write("f.las", lasBytes(s));
            auto r = loadPointCloud(path);
            ASSERT_TRUE(r.ok()) << r.error().message;
            ASSERT_EQ(r->scalar, Scalar::kFloat64);
            EXPECT_TRUE(r->floats.empty());
            ASSERT_EQ(r->size(), s.points.size());
            for (size_t i = 0; i < s.points.size(); ++i) {
                EXPECT_EQ(r->doubles[i], lasCoordinates(s, s.points[i])) << "point " << i;
            }
        }
    }
}

TEST_F(LasReader, ScaleAndOffsetAreAppliedInDouble) {
    LasSpec s;
    s.scale = {0.01, 0.01, 0.001};
    s.offset = {512000.0, 5400000.0, 250.0};
    s.points = {{{1, 1, 1}}, {{-3, 12345, -250000}}};
    const std::string path = write("utm.las", lasBytes(s));
    auto r = loadPointCloud(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    // Centimetres at y = 5.4e6 survive (float32 spacing there is 0.5 m).
    EXPECT_EQ(r->doubles[0], glm::dvec3(512000.01, 5400000.01, 250.001));
    EXPECT_EQ(r->doubles[1], glm::dvec3(511999.97, 5400123.45, 0.0));
    // loadPoints rounds the same file to float32.
    auto f = loadPoints(path);
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ((*f)[0], glm::vec3(512000.0f, 5400000.0f, 250.001f));
}

TEST_F(LasReader, VariableLengthRecordsAreSkipped) {
    LasSpec s;
    s.minor = 4;
    s.format = 6;
    s.vlrs = 3;
    s.points = samplePoints();
    auto r = loadPointCloud(write("vlr.las", lasBytes(s)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), s.points.size());
    for (size_t i = 0; i < s.points.size(); ++i) EXPECT_EQ(r->doubles[i], lasCoordinates(s, s.points[i]));
}

TEST_F(LasReader, GzippedLasLoads) {
    LasSpec s;
    s.points = samplePoints();
    auto r = loadPointCloud(write("z.las.gz", gzip(lasBytes(s))));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), s.points.size());
}

TEST_F(LasReader, ClassificationFilterLegacyFormats) {
    LasSpec s;
    s.format = 1;
    // Bits 5-7 of byte 15 are flags, not class: 2 | synthetic is class 2.
    s.points = {{{1, 0, 0}, 2}, {{2, 0, 0}, 6}, {{3, 0, 0}, 2, 0x20}, {{4, 0, 0}, 5, 0xE0}};
    const std::string path = write("c.las", lasBytes(s));
    auto ground = loadPointCloud(path, LoadOptions{{2}});
    ASSERT_TRUE(ground.ok()) << ground.error().message;
    ASSERT_EQ(ground->size(), 2u);
    EXPECT_EQ(ground->doubles[0].x, 0.01);
    EXPECT_EQ(ground->doubles[1].x, 0.03);
    auto two = loadPointCloud(path, LoadOptions{{6, 5}});
    ASSERT_TRUE(two.ok()) << two.error().message;
    ASSERT_EQ(two->size(), 2u);
    EXPECT_EQ(two->doubles[0].x, 0.02);
    EXPECT_EQ(two->doubles[1].x, 0.04);
    auto all = loadPointCloud(path);
    ASSERT_TRUE(all.ok()) << all.error().message;
    EXPECT_EQ(all->size(), 4u);
}

TEST_F(LasReader, ClassificationFilterExtendedFormats) {
    LasSpec s;
    s.minor = 4;
    s.format = 8;
    s.points = {{{1, 0, 0}, 2}, {{2, 0, 0}, 40}, {{3, 0, 0}, 255}, {{4, 0, 0}, 6}};
    const std::string path = write("c14.las", lasBytes(s));
    auto r = loadPointCloud(path, LoadOptions{{40, 255}});
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 2u);
    EXPECT_EQ(r->doubles[0].x, 0.02);
    EXPECT_EQ(r->doubles[1].x, 0.03);
}

TEST_F(LasReader, FilterThatKeepsNothingNamesTheClasses) {
    LasSpec s;
    s.points = samplePoints();  // classes 2, 6, 2, 9
    const std::string path = write("none.las", lasBytes(s));
    auto r = loadPointCloud(path, LoadOptions{{3, 17}});
    ASSERT_TRUE(isBadInput(r, path, "classification: none of the 4 points has class 3, 17"));
    EXPECT_NE(r.error().message.find("the file holds class 2, 6, 9"), std::string::npos) << r.error().message;
}

TEST_F(LasReader, OtherFormatsIgnoreTheClassFilter) {
    auto r = loadPointCloud(write("p.xyz", "1 2 3\n"), LoadOptions{{2}});
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 1u);
}

// ---- lies and damage ----------------------------------------------------------

TEST_F(LasReader, TruncatedRecords) {
    LasSpec s;
    s.format = 3;
    s.points = samplePoints();
    std::string bytes = lasBytes(s);
    bytes.resize(bytes.size() - 10);  // the last record is cut
    const std::string path = write("t.las", bytes);
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "the header declares 4 points of 34 bytes"));
}

TEST_F(LasReader, LegacyCountTooHigh) {
    LasSpec s;
    s.points = samplePoints();
    s.legacyCount = 5;
    const std::string path = write("lie.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 227: the header declares 5 points"));
}

TEST_F(LasReader, LegacyAndExtendedCountsDisagree) {
    LasSpec s;
    s.minor = 4;
    s.format = 1;
    s.points = samplePoints();
    s.legacyCount = 3;
    const std::string path = write("two.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path,
                           "byte offset 107: legacy point count 3 disagrees with the LAS 1.4 point count 4"));
}

TEST_F(LasReader, ExtendedCountPast32BitsInAShortFileIsRefused) {
    // 2^32 + 5 and 2^64 - 1 points declared, four in the file: refused from
    // the header (a reader trusting the count would allocate ~100 GB or more).
    for (uint64_t lie : {(uint64_t{1} << 32) + 5, std::numeric_limits<uint64_t>::max()}) {
        LasSpec s;
        s.minor = 4;
        s.format = 6;
        s.points = samplePoints();
        s.count = lie;
        const std::string path = write("big.las", lasBytes(s));
        EXPECT_TRUE(isBadInput(
            loadPointCloud(path), path,
            "byte offset 375: the header declares " + std::to_string(lie) + " points of 30 bytes"));
    }
}

TEST_F(LasReader, ZeroPointsIsBadInput) {
    LasSpec s;
    const std::string path = write("empty.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "contains no points"));
}

TEST_F(LasReader, ZeroScaleIsRefused) {
    for (size_t axis = 0; axis < 3; ++axis) {
        LasSpec s;
        s.points = samplePoints();
        s.scale[axis] = 0.0;
        const std::string path = write("s0.las", lasBytes(s));
        const std::string name(1, "XYZ"[axis]);
        EXPECT_TRUE(
            isBadInput(loadPointCloud(path), path,
                       "byte offset " + std::to_string(131 + 8 * axis) + ": " + name + " scale factor is 0"));
    }
}

TEST_F(LasReader, NonFiniteScaleOrOffsetIsRefused) {
    LasSpec s;
    s.points = samplePoints();
    s.scale[1] = std::numeric_limits<double>::infinity();
    std::string path = write("si.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 139: Y scale factor is not finite"));
    s.scale[1] = 0.01;
    s.offset[2] = std::numeric_limits<double>::quiet_NaN();
    path = write("on.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 171: Z offset is not finite"));
}

TEST_F(LasReader, InfiniteAfterScalingIsRefused) {
    LasSpec s;
    s.scale = {1e300, 1.0, 1.0};
    s.points = {{{1000, 0, 0}}, {{2147483647, 0, 0}}};  // 1e303 is finite, 2.1e309 is not
    const std::string path = write("inf.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path,
                           "point 1 (byte offset 247): X * scale + offset is not finite"));
}

TEST_F(LasReader, RecordLengthShorterThanTheFormat) {
    LasSpec s;
    s.format = 3;
    s.points = samplePoints();
    s.recordLength = 28;
    const std::string path = write("rl.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path,
                           "byte offset 105: point record length 28 is shorter than format 3's 34 bytes"));
}

TEST_F(LasReader, HeaderSizeSmallerThanTheVersion) {
    LasSpec s;
    s.minor = 4;
    s.points = samplePoints();
    s.headerSize = 227;
    const std::string path = write("h.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path,
                           "byte offset 94: header size 227 is smaller than LAS 1.4's 375"));
}

TEST_F(LasReader, PointOffsetInsideTheHeaderOrPastTheEnd) {
    LasSpec s;
    s.points = samplePoints();
    s.pointOffset = 100;
    std::string path = write("o.las", lasBytes(s));
    EXPECT_TRUE(
        isBadInput(loadPointCloud(path), path, "byte offset 96: offset to point data 100 is outside"));
    s.pointOffset = 1'000'000;
    path = write("o2.las", lasBytes(s));
    EXPECT_TRUE(
        isBadInput(loadPointCloud(path), path, "byte offset 96: offset to point data 1000000 is outside"));
}

TEST_F(LasReader, UnsupportedVersionAndFormat) {
    LasSpec s;
    s.points = samplePoints();
    s.minor = 5;
    std::string path = write("v.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 24: unsupported LAS version 1.5"));
    s.minor = 2;
    s.major = 2;
    path = write("v2.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "unsupported LAS version 2.2"));
    s.major = 1;
    s.format = 11;
    path = write("f.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 104: unsupported point data format 11"));
}

TEST_F(LasReader, NotLasAndTruncatedHeader) {
    std::string path = write("x.las", "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 0: not a LAS file"));
    LasSpec s;
    path = write("short.las", lasBytes(s).substr(0, 150));
    EXPECT_TRUE(
        isBadInput(loadPointCloud(path), path, "header: the file has 150 bytes, fewer than the 227-byte"));
    s.minor = 4;
    path = write("short14.las", lasBytes(s).substr(0, 300));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path,
                           "byte offset 94: header size 375 exceeds the file's 300 bytes"));
}

TEST_F(LasReader, LazIsRefusedWithHowToDecompress) {
    LasSpec s;
    s.points = samplePoints();
    for (const std::string name : {"scan.laz", "SCAN.LAZ", "scan.laz.gz"}) {
        const std::string path = write(name, lasBytes(s));
        auto r = loadPointCloud(path);
        ASSERT_TRUE(isBadInput(r, path, "compressed LAS (LAZ) is not read (Debian 12 has no LAZ library)"));
        EXPECT_NE(r.error().message.find("laszip -i in.laz -o out.las"), std::string::npos);
        EXPECT_NE(r.error().message.find("pdal translate in.laz out.las"), std::string::npos);
    }
    // A .las whose point format carries LASzip's compression bit.
    s.format = 0x80 | 3;
    const std::string path = write("packed.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path), path, "byte offset 104: compressed LAS (LAZ) is not read"));
}

TEST_F(LasReader, OutOfRangeClassIsBadInput) {
    LasSpec s;
    s.points = samplePoints();
    const std::string path = write("r.las", lasBytes(s));
    EXPECT_TRUE(isBadInput(loadPointCloud(path, LoadOptions{{256}}), path,
                           "classification: class 256 is outside 0..255"));
}

}  // namespace
}  // namespace rthdist::io::test
