// STL: binary (also one whose header starts with "solid") and ascii.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using StlReader = TempDirTest;

std::string binaryStl(const std::string& header80, const std::vector<glm::vec3>& corners, uint32_t declared) {
    ByteBuilder b;
    std::string header = header80;
    header.resize(80, ' ');
    b.text(header).put<uint32_t>(declared);
    for (size_t f = 0; f + 2 < corners.size(); f += 3) {
        b.put(0.0f).put(0.0f).put(1.0f);
        for (size_t c = 0; c < 3; ++c) b.put(corners[f + c].x).put(corners[f + c].y).put(corners[f + c].z);
        b.put<uint16_t>(0);
    }
    return b.str();
}

TEST_F(StlReader, BinaryKeepsEveryFacetVertex) {
    std::vector<glm::vec3> corners = threePoints();
    corners.insert(corners.end(), {{0, 0, 0}, {1, 0, 0}, {1.5f, -2.25f, 3.0f}});
    auto r = loadPoints(write("a.stl", binaryStl("binary", corners, 2)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, corners);
}

TEST_F(StlReader, BinaryWhoseHeaderSaysSolid) {
    auto r = loadPoints(write("s.stl", binaryStl("solid exported by a careless tool", threePoints(), 1)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(StlReader, Ascii) {
    const std::string text =
        "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 1.5 -2.25 3\n"
        "   vertex 0 0.001 -7.5\n   vertex 100 200.5 -300.25\n  endloop\n endfacet\nendsolid t\n";
    auto r = loadPoints(write("a.stl", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(StlReader, BinaryFacetCountLies) {
    const std::string path = write("lie.stl", binaryStl("binary", threePoints(), 1000000));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset 80: binary STL declares 1000000 facets"));
}

TEST_F(StlReader, TooShort) {
    const std::string path = write("short.stl", "abc");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset 0"));
}

TEST_F(StlReader, AsciiNonNumericNamesLine) {
    const std::string path =
        write("bad.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 1 oops 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 5: 'oops' is not a number"));
}

TEST_F(StlReader, AsciiWithoutFacetsHasNoPoints) {
    const std::string path = write("empty.stl", "solid t\nendsolid t\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "contains no points"));
}

TEST_F(StlReader, BinaryNanNamesVertex) {
    std::vector<glm::vec3> corners = threePoints();
    corners[2].x = std::numeric_limits<float>::infinity();
    const std::string path = write("inf.stl", binaryStl("binary", corners, 1));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "vertex 2: coordinate x is infinite"));
}

// ---- hardening (issue 15) ----------------------------------------------------

TEST_F(StlReader, BinaryWithSolidHeaderAndWrongSizeSaysBinary) {
    // Used to go down the ascii path and report "contains no points".
    const std::string path = write("solid_short.stl", binaryStl("solid exported", threePoints(), 2));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset 80: binary STL declares 2 facets"));
}

// A facet of two or four vertices would shift every triangle after it
// (triangle t is facet t's corners): refused, as is a vertex outside a
// facet and a file that ends inside one (truncated, possibly mid-number).
TEST_F(StlReader, AsciiFacetsHoldExactlyThreeVertices) {
    const std::string facet3 =
        "facet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 4 5 6\nvertex 7 8 9\nendloop\nendfacet\n";
    const std::string two =
        write("two.stl",
              "solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 4 5 6\nendloop\nendfacet\n" +
                  facet3 + "endsolid t\n");
    EXPECT_TRUE(
        isBadInput(loadPoints(two), two, "line 7: facet 0 has 2 vertices (an STL facet is a triangle)"));
    const std::string four = write("four.stl", "solid t\n" + facet3.substr(0, facet3.find("endloop")) +
                                                   "vertex 0 0 0\nendloop\nendfacet\n");
    EXPECT_TRUE(isBadInput(loadPoints(four), four, "line 7: facet 0 has more than 3 vertices"));
    const std::string cut =
        write("cut.stl", "solid t\n" + facet3 + "facet normal 0 0 1\nouter loop\nvertex 10 11 1");
    EXPECT_TRUE(isBadInput(loadPoints(cut), cut, "line 11: file ends inside facet 1 (line 9): truncated"));
    const std::string loose = write("loose.stl", "solid t\nvertex 1 2 3\n" + facet3);
    EXPECT_TRUE(isBadInput(loadPoints(loose), loose, "line 2: a vertex outside any facet"));
    const std::string open = write("open.stl", "solid t\nfacet normal 0 0 1\n" + facet3);
    EXPECT_TRUE(isBadInput(loadPoints(open), open, "line 3: facet 0 (line 2) has no endfacet"));
    const std::string values = write("values.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2\n");
    EXPECT_TRUE(isBadInput(loadPoints(values), values, "line 4: a vertex line with 2 values (x y z)"));
    // Two solids, and no endsolid at the end: read.
    auto r = loadPoints(write("two_solids.stl", "solid a\n" + facet3 + "endsolid a\nsolid b\n" + facet3));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 6u);
}

// Facets past the declared count are refused (points the header leaves
// out); fewer than a facet's 50 bytes of trailing padding are not.
TEST_F(StlReader, BinaryFacetsPastTheDeclaredCount) {
    std::vector<glm::vec3> corners = threePoints();
    corners.insert(corners.end(), {{0, 0, 0}, {1, 0, 0}, {1.5f, -2.25f, 3.0f}});
    const std::string more = write("more.stl", binaryStl("binary", corners, 1));
    EXPECT_TRUE(
        isBadInput(loadPoints(more), more,
                   "byte offset 80: binary STL declares 1 facets (134 bytes) but the file has 184 bytes: 1 "
                   "more facets' worth follow the declared ones"));
}

TEST_F(StlReader, BinaryWithSolidHeaderAndTrailingBytes) {
    // Trailing bytes shorter than a facet are ignored for binary STL, whatever the header says.
    const std::string path =
        write("solid_tail.stl", binaryStl("solid exported", threePoints(), 1) + std::string(7, '\0'));
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(StlReader, AsciiWithBomAndCrOnlyLineEnds) {
    const std::string text =
        "\xEF\xBB\xBFsolid t\r facet normal 0 0 1\r  outer loop\r   vertex 1.5 -2.25 3\r"
        "   vertex 0 0.001 -7.5\r   vertex 100 200.5 -300.25\r  endloop\r endfacet\rendsolid t\r";
    auto r = loadPoints(write("bom.stl", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
    const std::string bad = write("crbad.stl", "solid t\rfacet normal 0 0 1\router loop\rvertex 1 q 3\r");
    EXPECT_TRUE(isBadInput(loadPoints(bad), bad, "line 4: 'q' is not a number"));
}

}  // namespace
}  // namespace rthdist::io::test
