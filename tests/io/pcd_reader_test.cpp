// PCD: ascii and binary, fields in any order, size, type and count.
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

TEST_F(PcdReader, BinaryTruncated) {
    ByteBuilder b;
    b.text("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 100\nDATA binary\n");
    b.put(1.f).put(2.f).put(3.f);
    const std::string path = write("t.pcd", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
}

TEST_F(PcdReader, CompressedUnsupported) {
    const std::string path =
        write("c.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA binary_compressed\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 5: unsupported DATA 'binary_compressed'"));
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
