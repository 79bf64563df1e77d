// PCD: ascii, binary and binary_compressed, fields in any order, size, type and count.
#include <lzf.h>

#include <random>

#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using PcdReader = TempDirTest;

TEST_F(PcdReader, Ascii) {
    const std::string text =
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n"
        "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
        "1.5 -2.25 3 4808703\n0 0.001 -7.5 0\n100 200.5 -300.25 1\n";
    auto r = loadPoints(write("a.pcd", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(PcdReader, BinaryMixedTypesAndCounts) {
    // normal (3 floats) first, then z as double, x as float, y as int16.
    ByteBuilder b;
    b.text(
        "VERSION .7\nFIELDS normal z x y\nSIZE 4 8 4 2\nTYPE F F F I\nCOUNT 3 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        "DATA binary\n");
    b.put(0.f).put(0.f).put(1.f).put(3.0).put(1.5f).put<int16_t>(-2);
    b.put(0.f).put(0.f).put(1.f).put(-7.5).put(0.25f).put<int16_t>(9);
    auto r = loadPoints(write("b.pcd", b.str()));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1.5f, -2, 3}, {0.25f, 9, -7.5f}}));
}

// Rows past POINTS would be points dropped unseen: nonzero bytes after the
// declared rows are refused, zeros (PCL pads its files to a page) are not.
TEST_F(PcdReader, BinaryDataPastTheDeclaredPoints) {
    ByteBuilder b;
    b.text("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA binary\n");
    const size_t body = b.str().size();
    b.put(1.f).put(2.f).put(3.f);
    const std::string padded = write("pad.pcd", b.str() + std::string(4000, '\0'));
    auto r = loadPoints(padded);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}}));
    b.put(4.f).put(5.f).put(6.f);
    const std::string more = write("more.pcd", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(more), more,
                           "byte offset " + std::to_string(body + 12) +
                               ": the header declares 1 points of 12 bytes, but data follows them"));
}

TEST_F(PcdReader, BinaryTruncated) {
    ByteBuilder b;
    b.text("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 100\nDATA binary\n");
    b.put(1.f).put(2.f).put(3.f);
    const std::string path = write("t.pcd", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
}

// A binary_compressed body as PCL writes it (pcl::io::savePCDFileBinaryCompressed):
// the fields' columns one after another, LZF-compressed, after the two sizes.
std::string compressedBody(const std::string& columns) {
    std::string out(columns.size() + columns.size() / 16 + 64, '\0');
    const unsigned n =
        lzf_compress(columns.data(), unsigned(columns.size()), out.data(), unsigned(out.size()));
    EXPECT_GT(n, 0u);
    out.resize(n);
    ByteBuilder b;
    b.put<uint32_t>(n).put<uint32_t>(uint32_t(columns.size()));
    return b.str() + out;
}

TEST_F(PcdReader, CompressedColumnsMatchTheBinaryRows) {
    // x y z as floats beside a colour: 1000 points, rows and columns of the same values.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-50.f, 50.f);
    const size_t n = 1000;
    std::vector<float> xyz(3 * n);
    for (float& v : xyz) v = u(rng);
    const std::string head =
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " +
        std::to_string(n) + "\nHEIGHT 1\nPOINTS " + std::to_string(n) + "\n";
    ByteBuilder rows, columns;
    rows.text(head + "DATA binary\n");
    for (size_t i = 0; i < n; ++i)
        rows.put(xyz[3 * i]).put(xyz[3 * i + 1]).put(xyz[3 * i + 2]).put<uint32_t>(7);
    for (int axis = 0; axis < 3; ++axis)
        for (size_t i = 0; i < n; ++i) columns.put(xyz[3 * i + size_t(axis)]);
    for (size_t i = 0; i < n; ++i) columns.put<uint32_t>(uint32_t(i));
    auto binary = loadPoints(write("rows.pcd", rows.str()));
    ASSERT_TRUE(binary.ok()) << binary.error().message;
    auto compressed =
        loadPoints(write("columns.pcd", head + "DATA binary_compressed\n" + compressedBody(columns.str())));
    ASSERT_TRUE(compressed.ok()) << compressed.error().message;
    ASSERT_EQ(compressed->size(), n);
    EXPECT_EQ(*compressed, *binary);
    EXPECT_EQ((*compressed)[999], glm::vec3(xyz[2997], xyz[2998], xyz[2999]));
}

TEST_F(PcdReader, CompressedMixedTypesAndCounts) {
    // As BinaryMixedTypesAndCounts: the axes' columns of different strides
    // (normal 12 bytes a point, z 8, x 4, y 2).
    ByteBuilder columns;
    columns.put(0.f).put(0.f).put(1.f).put(0.f).put(0.f).put(1.f);  // normal
    columns.put(3.0).put(-7.5);                                     // z
    columns.put(1.5f).put(0.25f);                                   // x
    columns.put<int16_t>(-2).put<int16_t>(9);                       // y
    const std::string head =
        "VERSION .7\nFIELDS normal z x y\nSIZE 4 8 4 2\nTYPE F F F I\nCOUNT 3 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        "DATA binary_compressed\n";
    auto r = loadPoints(write("m.pcd", head + compressedBody(columns.str())));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1.5f, -2, 3}, {0.25f, 9, -7.5f}}));
}

// A file PCL itself compressed (tests/io/data/README.md) reads as its ascii source.
TEST_F(PcdReader, PclsBinaryCompressedReadsAsItsAsciiSource) {
    const std::string dir = RTHDIST_IO_FIXTURES_DIR;
    auto ascii = loadPointCloud(dir + "/pcl_ascii.pcd");
    auto compressed = loadPointCloud(dir + "/pcl_binary_compressed.pcd");
    ASSERT_TRUE(ascii.ok()) << ascii.error().message;
    ASSERT_TRUE(compressed.ok()) << compressed.error().message;
    ASSERT_EQ(compressed->scalar, Scalar::kFloat32);
    ASSERT_EQ(compressed->floats.size(), 300u);
    ASSERT_EQ(ascii->doubles.size(), 300u);
    for (size_t i = 0; i < 300; ++i)  // the ascii values are the floats' shortest round trips
        EXPECT_EQ(glm::dvec3(compressed->floats[i]), ascii->doubles[i]) << "point " << i;
}

TEST_F(PcdReader, CompressedErrorsNameTheOffset) {
    const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 2\nDATA binary_compressed\n";
    const size_t body = head.size();
    ByteBuilder columns;
    columns.put(1.f).put(2.f).put(3.f).put(4.f).put(5.f).put(6.f);
    const std::string good = compressedBody(columns.str());
    ASSERT_TRUE(loadPoints(write("ok.pcd", head + good)).ok());
    const std::string at = "byte offset " + std::to_string(body);
    const std::string sizes = write("s.pcd", head + "abc");
    EXPECT_TRUE(
        isBadInput(loadPoints(sizes), sizes, at + ": binary_compressed: the two 4-byte sizes are missing"));
    const std::string cut = write("c.pcd", head + good.substr(0, good.size() - 1));
    EXPECT_TRUE(isBadInput(loadPoints(cut), cut, at + ": binary_compressed: declares"));
    // 2 points of 12 bytes are 24 bytes; a stream that says 25 is refused.
    std::string wrong = good;
    wrong[4] = 25;
    const std::string size = write("w.pcd", head + wrong);
    EXPECT_TRUE(isBadInput(loadPoints(size), size, "need 24 bytes, the stream declares 25"));
    // Past LZF's 88x: 4 bytes cannot hold 1M points of 12 bytes.
    ByteBuilder bomb;
    bomb.put<uint32_t>(4).put<uint32_t>(12000000).put<uint32_t>(0);
    const std::string big =
        write("b.pcd",
              "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1000000\nDATA binary_compressed\n" + bomb.str());
    EXPECT_TRUE(isBadInput(loadPoints(big), big, "cannot inflate to 12000000 (at most 88 times)"));
    // A back reference before the start of the output: corrupt.
    ByteBuilder corrupt;
    corrupt.put<uint32_t>(3).put<uint32_t>(24).put<uint8_t>(0x20).put<uint8_t>(0x10).put<uint8_t>(0);
    const std::string bad = write("x.pcd", head + corrupt.str());
    EXPECT_TRUE(isBadInput(
        loadPoints(bad), bad,
        "byte offset " + std::to_string(body + 8) + ": binary_compressed: the LZF stream is corrupt"));
    ByteBuilder nan;
    nan.put(1.f).put(std::numeric_limits<float>::quiet_NaN()).put(2.f).put(3.f).put(4.f).put(5.f);
    const std::string n = write("n.pcd", head + compressedBody(nan.str()));
    EXPECT_TRUE(isBadInput(loadPoints(n), n, "vertex 1: coordinate x is NaN"));
}

TEST_F(PcdReader, HeaderErrors) {
    const std::string noZ = write("noz.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA ascii\n1 2\n");
    EXPECT_TRUE(isBadInput(loadPoints(noZ), noZ, "header: no field 'z'"));
    const std::string sizes =
        write("sz.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(sizes), sizes, "line 2"));
    const std::string type =
        write("ty.pcd", "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(type), type, "field z: unsupported TYPE F with SIZE 2"));
    const std::string noData = write("nd.pcd", "FIELDS x y z\nSIZE 4 4 4\n");
    EXPECT_TRUE(isBadInput(loadPoints(noData), noData, "header: no DATA line"));
}

TEST_F(PcdReader, WidthTimesHeightMustBePoints) {
    const std::string path = write(
        "wh.pcd",
        "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "header: WIDTH * HEIGHT is 3 but POINTS is 2"));
}

TEST_F(PcdReader, AsciiErrorsNameLineOrVertex) {
    const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nDATA ascii\n";
    const std::string word = write("w.pcd", head + "1 2 3\n1 2 zz\n");
    EXPECT_TRUE(isBadInput(loadPoints(word), word, "line 8: 'zz' is not a number"));
    const std::string nan = write("n.pcd", head + "1 2 3\nnan nan nan\n");
    EXPECT_TRUE(isBadInput(loadPoints(nan), nan, "vertex 1: coordinate x is NaN"));
    const std::string few = write("f.pcd", head + "1 2 3\n1 2          \n");
    EXPECT_TRUE(isBadInput(loadPoints(few), few, "line 8"));
}

}  // namespace
}  // namespace rthdist::io::test
