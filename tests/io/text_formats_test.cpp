// XYZ, OBJ and OFF: round trips, what is skipped, and bad input.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using TextFormats = TempDirTest;

TEST_F(TextFormats, XyzColumnsCommentsSeparators) {
    const std::string text =
        "# x y z intensity\n\n1.5 -2.25 3 77\n0,0.001,-7.5\n  +100\t200.5;-300.25  \n// end\n";
    auto r = loadPoints(write("a.xyz", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

// Decimal commas ("1,5 2,5 3,5") would read as 1, 5, 2: a line whose
// values are separated both by blanks alone and by commas is refused.
TEST_F(TextFormats, XyzDecimalCommasAreRefused) {
    const std::string path = write("comma.xyz", "1.5 2.5 3.5\n1,5 2,5 3,5\n");
    EXPECT_TRUE(
        isBadInput(loadPoints(path), path, "line 2: values separated both by blanks alone and by commas"));
    auto r = loadPoints(write("csv.xyz", "1, 2, 3\n4 ,5 ,6\n7,8,9,255\n"));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 3u);
}

TEST_F(TextFormats, TxtIsXyz) {
    auto r = loadPoints(write("a.txt", "1 2 3"));  // no final newline
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}}));
}

TEST_F(TextFormats, XyzNonNumericNamesLine) {
    const std::string path = write("bad.xyz", "1 2 3\n# c\n4 5 six\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 3: 'six' is not a number"));
}

TEST_F(TextFormats, XyzTooFewColumnsNamesLine) {
    const std::string path = write("two.xyz", "1 2 3\n4 5\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 2"));
}

TEST_F(TextFormats, XyzOnlyCommentsHasNoPoints) {
    const std::string path = write("c.xyz", "# nothing\n\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "file: contains no points"));
}

TEST_F(TextFormats, XyzNanNamesVertex) {
    const std::string path = write("nan.xyz", "1 2 3\n4 5 6\nnan 1 1\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "vertex 2: coordinate x is NaN"));
}

TEST_F(TextFormats, ObjVerticesOnly) {
    const std::string text =
        "# exported\nmtllib a.mtl\no thing\nv 1.5 -2.25 3\nvn 0 0 1\nvt 0.5 0.5\n"
        "v 0 0.001 -7.5 1.0\nv\t100 200.5 -300.25 0.1 0.2 0.3\nf 1 2 3\nf 1/1/1 2/1/1 3/1/1\n";
    auto r = loadPoints(write("a.obj", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(TextFormats, ObjBadVertexNamesLine) {
    const std::string path = write("bad.obj", "v 1 2 3\nvn 1 1 1\nv 1 2\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 3"));
    const std::string word = write("word.obj", "v 1 2 3\nv 1 x 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(word), word, "line 2: 'x' is not a number"));
}

TEST_F(TextFormats, ObjWithoutVerticesHasNoPoints) {
    const std::string path = write("none.obj", "# only faces\nf 1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "contains no points"));
}

TEST_F(TextFormats, OffVariantsAndComments) {
    const std::string body =
        "1.5 -2.25 3\n0 0.001 -7.5 # comment\n\n100 200.5 -300.25 255 0 0 255\n3 0 1 2\n";
    for (const std::string head :
         {"OFF\n3 1 0\n", "OFF 3 1 0\n", "# c\nCOFF\n# counts\n3 1 0\n", "NOFF\n3 1 0\n"}) {
        auto r = loadPoints(write("a.off", head + body));
        ASSERT_TRUE(r.ok()) << head << r.error().message;
        EXPECT_EQ(*r, threePoints()) << head;
    }
}

TEST_F(TextFormats, OffBadInput) {
    const std::string notOff = write("n.off", "PLY\n3 1 0\n");
    EXPECT_TRUE(isBadInput(loadPoints(notOff), notOff, "line 1"));
    const std::string fourD = write("4.off", "4OFF\n1 0 0\n1 2 3 4\n");
    EXPECT_TRUE(isBadInput(loadPoints(fourD), fourD, "line 1: unsupported OFF variant '4OFF'"));
    const std::string binary = write("b.off", "OFF BINARY\n");
    EXPECT_TRUE(isBadInput(loadPoints(binary), binary, "line 1"));
    const std::string count = write("c.off", "OFF\nthree 1 0\n");
    EXPECT_TRUE(isBadInput(loadPoints(count), count, "line 2: bad vertex count"));
    const std::string huge = write("h.off", "OFF\n99999999999 1 0\n1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(huge), huge, "line 2: declares 99999999999 vertices"));
    const std::string shortFile = write("s.off", "OFF\n3 0 0\n1 2 3\n4 5 6\n            \n");
    EXPECT_TRUE(isBadInput(loadPoints(shortFile), shortFile, "file ends at vertex 2 of 3"));
    const std::string word = write("w.off", "OFF\n2 0 0\n1 2 3\n4 y 6\n");
    EXPECT_TRUE(isBadInput(loadPoints(word), word, "line 4: 'y' is not a number"));
    const std::string zero = write("z.off", "OFF\n0 0 0\n");
    EXPECT_TRUE(isBadInput(loadPoints(zero), zero, "contains no points"));
    const std::string inf = write("i.off", "OFF\n1 0 0\n1 2 1e39\n");
    EXPECT_TRUE(isBadInput(loadPoints(inf), inf, "vertex 0: coordinate z"));
}

// ---- hardening (issue 15): byte order marks and CR-only line ends ------------

TEST_F(TextFormats, Utf8BomBeforeTheFirstObjVertex) {
    // The BOM glued to "v" used to drop the first vertex silently.
    auto r = loadPoints(write("bom.obj", "\xEF\xBB\xBFv 1.5 -2.25 3\nv 0 0.001 -7.5\nv 100 200.5 -300.25\n"));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(TextFormats, Utf8BomInXyzOffAndPcd) {
    // The BOM used to be reported as part of a number ("'\xEF\xBB\xBF1' is not a number").
    const std::string bom = "\xEF\xBB\xBF";
    auto xyz = loadPoints(write("bom.xyz", bom + "1 2 3\n4 5 6\n"));
    ASSERT_TRUE(xyz.ok()) << xyz.error().message;
    EXPECT_EQ(*xyz, (std::vector<glm::vec3>{{1, 2, 3}, {4, 5, 6}}));
    auto off = loadPoints(write("bom.off", bom + "OFF\n1 0 0\n1 2 3\n"));
    ASSERT_TRUE(off.ok()) << off.error().message;
    EXPECT_EQ(*off, (std::vector<glm::vec3>{{1, 2, 3}}));
    auto pcd =
        loadPoints(write("bom.pcd", bom + "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                                          "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n"));
    ASSERT_TRUE(pcd.ok()) << pcd.error().message;
    EXPECT_EQ(*pcd, (std::vector<glm::vec3>{{1, 2, 3}}));
}

TEST_F(TextFormats, CrOnlyLineEndsReadEveryPoint) {
    // Lone CR line ends used to make one line of the file: 1 point of 3.
    const std::vector<glm::vec3> want = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
    auto obj = loadPoints(write("cr.obj", "v 1 2 3\rv 4 5 6\rv 7 8 9\r"));
    ASSERT_TRUE(obj.ok()) << obj.error().message;
    EXPECT_EQ(*obj, want);
    auto xyz = loadPoints(write("cr.xyz", "1 2 3\r4 5 6\r7 8 9\r"));
    ASSERT_TRUE(xyz.ok()) << xyz.error().message;
    EXPECT_EQ(*xyz, want);
    auto off = loadPoints(write("cr.off", "OFF\r3 0 0\r1 2 3\r4 5 6\r7 8 9\r"));
    ASSERT_TRUE(off.ok()) << off.error().message;
    EXPECT_EQ(*off, want);
    auto pcd = loadPoints(write("cr.pcd",
                                "FIELDS x y z\rSIZE 4 4 4\rTYPE F F F\rCOUNT 1 1 1\rWIDTH 3\r"
                                "HEIGHT 1\rPOINTS 3\rDATA ascii\r1 2 3\r4 5 6\r7 8 9\r"));
    ASSERT_TRUE(pcd.ok()) << pcd.error().message;
    EXPECT_EQ(*pcd, want);
}

TEST_F(TextFormats, CrOnlyLineNumbersInMessages) {
    const std::string path = write("crbad.xyz", "1 2 3\r4 5 6\r7 x 9\r");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 3: 'x' is not a number"));
    const std::string mixed = write("mixed.obj", "v 1 2 3\r\nv 4 5 6\rv 7 8 9\nv 1 y 1\n");
    EXPECT_TRUE(isBadInput(loadPoints(mixed), mixed, "line 4: 'y' is not a number"));
}

}  // namespace
}  // namespace rthdist::io::test
