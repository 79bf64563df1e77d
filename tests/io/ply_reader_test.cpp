// PLY: every format and byte order, every numeric type for x/y/z, skipped
// properties/lists/elements (also before the vertex element), and each
// malformed-input case.
#include <limits>

#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using PlyReader = TempDirTest;

std::string header(const std::string& format, const std::string& body) {
    return "ply\nformat " + format + " 1.0\n" + body + "end_header\n";
}

const std::string kXyzFloat = "property float x\nproperty float y\nproperty float z\n";

TEST_F(PlyReader, AsciiWithExtraPropertiesFacesAndComments) {
    const std::string text =
        "ply\nformat ascii 1.0\ncomment zipper output\nobj_info num_cols 512\n"
        "element vertex 3\n" +
        kXyzFloat +
        "property float confidence\nproperty float intensity\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "1.5 -2.25 3 0.85 0.5\n0 0.001 -7.5 0.9 0.5\n100 200.5 -300.25 0.4 0.5\n3 0 1 2\n";
    auto r = loadPoints(write("a.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(PlyReader, CrLfHeaderAndBody) {
    const std::string text =
        "ply\r\nformat ascii 1.0\r\nelement vertex 1\r\nproperty float x\r\nproperty float y\r\n"
        "property float z\r\nend_header\r\n1 2 3\r\n";
    auto r = loadPoints(write("crlf.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}}));
}

TEST_F(PlyReader, AsciiPropertyOrderAndVertexList) {
    // z before x, a list inside the vertex element, an unused property first.
    const std::string text = header("ascii",
                                    "element vertex 2\nproperty uchar red\nproperty double z\n"
                                    "property list uchar float normals\nproperty int x\nproperty short y\n") +
                             "255 3 2 0.5 0.5 1 2\n0 -6 0 4 5\n";
    auto r = loadPoints(write("order.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}, {4, 5, -6}}));
}

TEST_F(PlyReader, AsciiElementsBeforeVertexAreSkipped) {
    // range_grid as in the Stanford range scans, but placed before the vertices;
    // one item per line.
    const std::string text =
        header("ascii",
               "element range_grid 4\nproperty list uchar int vertex_indices\n"
               "element face 2\nproperty list uchar int vertex_indices\nproperty uchar flags\n"
               "element vertex 2\n" +
                   kXyzFloat) +
        "0\n1 0\n0\n2 0 1\n3 0 1 1 7\n3 1 0 1 8\n1 2 3\n4 5 6\n";
    auto r = loadPoints(write("before.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}, {4, 5, 6}}));
}

TEST_F(PlyReader, ElementWithoutPropertiesAndHugeCountIsSkippedInstantly) {
    const std::string text =
        header("ascii", "element nothing 18446744073709551615\nelement vertex 1\n" + kXyzFloat) + "1 2 3\n";
    auto r = loadPoints(write("empty_element.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 1u);
}

// Builds a binary PLY whose x/y/z have the given type name, with a leading
// list-carrying element and a trailing face element.
template <class T>
std::string binaryPly(const std::string& typeName, bool bigEndian, const std::vector<T>& xyz) {
    ByteBuilder b(bigEndian);
    b.text(header(bigEndian ? "binary_big_endian" : "binary_little_endian",
                  "comment typed\nelement tristrips 1\nproperty list int int vertex_indices\n"
                  "element vertex " +
                      std::to_string(xyz.size() / 3) +
                      "\nproperty float confidence\n"
                      "property " +
                      typeName + " x\nproperty " + typeName + " y\nproperty " + typeName +
                      " z\n"
                      "property list uchar float extra\n"
                      "element face 1\nproperty list uchar int vertex_indices\n"));
    b.put<int32_t>(4).put<int32_t>(0).put<int32_t>(1).put<int32_t>(-1).put<int32_t>(2);
    for (size_t i = 0; i < xyz.size(); i += 3) {
        b.put<float>(0.5f);
        b.put<T>(xyz[i]);
        b.put<T>(xyz[i + 1]);
        b.put<T>(xyz[i + 2]);
        b.put<uint8_t>(2).put<float>(9.0f).put<float>(9.0f);
    }
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    return b.str();
}

template <class T>
void expectTypeRoundTrip(PlyReader& t, const std::string& typeName) {
    const std::vector<T> xyz =
        std::is_signed_v<T> ? std::vector<T>{1, 2, 3, T(-4), 5, 127} : std::vector<T>{1, 2, 3, 4, 5, 127};
    const std::vector<glm::vec3> want = {{float(xyz[0]), float(xyz[1]), float(xyz[2])},
                                         {float(xyz[3]), float(xyz[4]), float(xyz[5])}};
    for (bool big : {false, true}) {
        const std::string path =
            t.write(typeName + (big ? "_be.ply" : "_le.ply"), binaryPly<T>(typeName, big, xyz));
        auto r = loadPoints(path);
        ASSERT_TRUE(r.ok()) << typeName << ": " << r.error().message;
        EXPECT_EQ(*r, want) << typeName << (big ? " big endian" : " little endian");
    }
}

TEST_F(PlyReader, BinaryEveryCoordinateTypeBothByteOrders) {
    expectTypeRoundTrip<int8_t>(*this, "char");
    expectTypeRoundTrip<int8_t>(*this, "int8");
    expectTypeRoundTrip<uint8_t>(*this, "uchar");
    expectTypeRoundTrip<uint8_t>(*this, "uint8");
    expectTypeRoundTrip<int16_t>(*this, "short");
    expectTypeRoundTrip<int16_t>(*this, "int16");
    expectTypeRoundTrip<uint16_t>(*this, "ushort");
    expectTypeRoundTrip<uint16_t>(*this, "uint16");
    expectTypeRoundTrip<int32_t>(*this, "int");
    expectTypeRoundTrip<int32_t>(*this, "int32");
    expectTypeRoundTrip<uint32_t>(*this, "uint");
    expectTypeRoundTrip<uint32_t>(*this, "uint32");
    expectTypeRoundTrip<float>(*this, "float");
    expectTypeRoundTrip<float>(*this, "float32");
    expectTypeRoundTrip<double>(*this, "double");
    expectTypeRoundTrip<double>(*this, "float64");
}

TEST_F(PlyReader, BinaryFractionalFloatsExact) {
    ByteBuilder b(true);
    b.text(header("binary_big_endian", "element vertex 3\n" + kXyzFloat));
    for (const glm::vec3& p : threePoints()) b.put(p.x).put(p.y).put(p.z);
    auto r = loadPoints(write("be.ply", b.str()));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(PlyReader, GzippedBinary) {
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 3\n" + kXyzFloat));
    for (const glm::vec3& p : threePoints()) b.put(p.x).put(p.y).put(p.z);
    auto r = loadPoints(write("le.ply.gz", gzip(b.str())));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

// ---- bad input ---------------------------------------------------------------

TEST_F(PlyReader, NotPly) {
    const std::string path = write("x.ply", "solid cube\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 1"));
}

TEST_F(PlyReader, BadFormatLine) {
    const std::string path =
        write("fmt.ply", header("binary_middle_endian", "element vertex 1\n" + kXyzFloat) + "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 2: unsupported format 'binary_middle_endian'"));
    const std::string noFormat =
        write("nofmt.ply", "ply\nelement vertex 1\n" + kXyzFloat + "end_header\n1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(noFormat), noFormat, "header: no 'format' line"));
    const std::string empty = write("emptyfmt.ply", "ply\nformat\nend_header\n");
    EXPECT_TRUE(isBadInput(loadPoints(empty), empty, "line 2"));
}

TEST_F(PlyReader, UnsupportedPropertyType) {
    const std::string path = write("type.ply", header("ascii",
                                                      "element vertex 1\nproperty int128 x\n"
                                                      "property float y\nproperty float z\n") +
                                                   "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 4: unsupported property type 'int128'"));
    const std::string list = write("listtype.ply", header("ascii",
                                                          "element face 1\nproperty list float int v\n"
                                                          "element vertex 1\n" +
                                                              kXyzFloat) +
                                                       "0\n1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(list), list, "line 4: unsupported list count type 'float'"));
}

TEST_F(PlyReader, MalformedHeaderLines) {
    const std::string count =
        write("count.ply", header("ascii", "element vertex many\n" + kXyzFloat) + "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(count), count, "line 3"));
    const std::string keyword =
        write("kw.ply", header("ascii", "element vertex 1\n" + kXyzFloat + "colour red\n"));
    EXPECT_TRUE(isBadInput(loadPoints(keyword), keyword, "line 7: unknown header keyword 'colour'"));
    const std::string orphan = write("orphan.ply", header("ascii", "property float x\n"));
    EXPECT_TRUE(isBadInput(loadPoints(orphan), orphan, "line 3"));
    const std::string noEnd = write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n" + kXyzFloat);
    EXPECT_TRUE(isBadInput(loadPoints(noEnd), noEnd, "header: no 'end_header'"));
}

TEST_F(PlyReader, MissingVertexElementOrCoordinate) {
    const std::string noVertex =
        write("nov.ply", header("ascii", "element face 0\nproperty list uchar int v\n"));
    EXPECT_TRUE(isBadInput(loadPoints(noVertex), noVertex, "no 'vertex' element"));
    const std::string noZ =
        write("noz.ply", header("ascii", "element vertex 1\nproperty float x\nproperty float y\n") + "1 2\n");
    EXPECT_TRUE(isBadInput(loadPoints(noZ), noZ, "element vertex: no property 'z'"));
}

TEST_F(PlyReader, ZeroVertices) {
    const std::string path =
        write("zero.ply", header("binary_little_endian", "element vertex 0\n" + kXyzFloat));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "file: contains no points"));
}

TEST_F(PlyReader, TruncatedBinaryBody) {
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 10\n" + kXyzFloat));
    for (int i = 0; i < 3 * 3; ++i) b.put<float>(1.0f);
    const std::string path = write("trunc.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "element vertex declares 10"));
}

TEST_F(PlyReader, HugeCountRejectedBeforeAllocating) {
    // 2^61 vertices: allocating first would throw bad_alloc or be killed.
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 2305843009213693952\n" + kXyzFloat));
    b.put(1.0f).put(2.0f).put(3.0f);
    const std::string path = write("huge.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
    const std::string ascii =
        write("hugea.ply", header("ascii", "element vertex 2305843009213693952\n" + kXyzFloat) + "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(ascii), ascii, "element vertex"));
}

TEST_F(PlyReader, TruncatedListElementBeforeVertex) {
    ByteBuilder b;
    b.text(header("binary_little_endian",
                  "element tristrips 1\nproperty list int int vertex_indices\n"
                  "element vertex 1\n" +
                      kXyzFloat));
    b.put<int32_t>(1000000).put<int32_t>(1).put<int32_t>(2);  // the list claims far more than the file holds
    const std::string path = write("strip.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "element tristrips"));
}

TEST_F(PlyReader, NegativeListLength) {
    ByteBuilder b;
    b.text(header("binary_little_endian",
                  "element face 1\nproperty list int int v\nelement vertex 1\n" + kXyzFloat));
    b.put<int32_t>(-3).put(1.0f).put(2.0f).put(3.0f);
    const std::string path = write("neg.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "negative list length"));
}

TEST_F(PlyReader, NanInBinaryNamesVertex) {
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 3\n" + kXyzFloat));
    b.put(1.0f).put(2.0f).put(3.0f);
    b.put(1.0f).put(std::numeric_limits<float>::quiet_NaN()).put(3.0f);
    b.put(1.0f).put(2.0f).put(3.0f);
    const std::string path = write("nan.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "vertex 1: coordinate y is NaN"));
}

TEST_F(PlyReader, InfAndOverflowInAsciiNameVertex) {
    const std::string inf =
        write("inf.ply", header("ascii", "element vertex 2\n" + kXyzFloat) + "1 2 3\n1 2 -inf\n");
    EXPECT_TRUE(isBadInput(loadPoints(inf), inf, "vertex 1: coordinate z is infinite"));
    const std::string big = write("big.ply", header("ascii",
                                                    "element vertex 1\nproperty double x\nproperty double y\n"
                                                    "property double z\n") +
                                                 "1e300 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(big), big, "vertex 0: coordinate x"));
}

TEST_F(PlyReader, NonNumericAsciiNamesLine) {
    const std::string path =
        write("word.ply", header("ascii", "element vertex 2\n" + kXyzFloat) + "1 2 3\n1 two 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 9: vertex 1 property y: 'two' is not a number"));
}

TEST_F(PlyReader, AsciiBodyEndsEarly) {
    const std::string path = write(
        "short.ply", header("ascii", "element vertex 3\n" + kXyzFloat) + "1 2 3\n4 5 6\n7 8            ");
    EXPECT_TRUE(
        isBadInput(loadPoints(path), path, "line 10: element vertex item 2: the line ends after 2 values"));
}

// ---- hardening (issue 15): counts that do not match the body ---------------

TEST_F(PlyReader, AsciiVertexCountOneTooHighDoesNotReadTheFace) {
    // Read token by token, "3 0 1 2" became vertex (3, 0, 1).
    const std::string text = header("ascii", "element vertex 4\n" + kXyzFloat +
                                                 "element face 1\nproperty list uchar int vertex_indices\n") +
                             "1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n";
    const std::string path = write("count_high.ply", text);
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "element face: declares 1 items (one per line)"));
    // Same with a face line of exactly three values.
    const std::string three = write("count_high3.ply", header("ascii", "element vertex 3\n" + kXyzFloat +
                                                                           "element face 1\nproperty list "
                                                                           "uchar int vertex_indices\n") +
                                                           "1 2 3\n4 5 6\n2 0 1\n");
    EXPECT_TRUE(isBadInput(loadPoints(three), three, "element face"));
}

TEST_F(PlyReader, AsciiExtraValueOnAVertexLineIsAnError) {
    // Read token by token, the stray 9 shifted every later vertex.
    const std::string path =
        write("extra.ply", header("ascii", "element vertex 2\n" + kXyzFloat) + "1 2 3 9\n4 5 6\n7 8 9\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 8: element vertex item 0: more values"));
}

TEST_F(PlyReader, AsciiTextAfterTheLastElementIsAnError) {
    const std::string path =
        write("low.ply", header("ascii", "element vertex 2\n" + kXyzFloat) + "1 2 3\n4 5 6\n7 8 9\n\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 10: text after the last declared element"));
}

TEST_F(PlyReader, BinaryVertexCountTooHighDoesNotReadFaceBytes) {
    // 15-byte vertices (x y z float, r g b uchar) and two triangles: a count
    // one too high took the first face and 2 bytes of the second as a vertex.
    ByteBuilder b;
    b.text(
        header("binary_little_endian", "element vertex 4\n" + kXyzFloat +
                                           "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                                           "element face 2\nproperty list uchar int vertex_indices\n"));
    for (const glm::vec3& p : threePoints())
        b.put(p.x).put(p.y).put(p.z).put<uint8_t>(1).put<uint8_t>(2).put<uint8_t>(3);
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    b.put<uint8_t>(3).put<int32_t>(2).put<int32_t>(1).put<int32_t>(0);
    const std::string path = write("count_high_bin.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
}

TEST_F(PlyReader, BinaryCountTooHighForTheElementsAfterTheVertices) {
    // The vertices fit; the face element after them cannot.
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 4\n" + kXyzFloat +
                                              "element face 3\nproperty list uchar int vertex_indices\n"));
    for (int i = 0; i < 4; ++i) b.put(1.0f).put(2.0f).put(3.0f);
    b.put<uint8_t>(0);
    const std::string path = write("faces_missing.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "element face declares 3 items"));
}

TEST_F(PlyReader, BinaryBytesAfterTheLastElementAreAnError) {
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 2\n" + kXyzFloat));
    for (int i = 0; i < 3; ++i) b.put(1.0f).put(2.0f).put(3.0f);
    const std::string path = write("count_low_bin.ply", b.str());
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "12 bytes follow the last declared element"));
    // A final newline or NUL padding is tolerated.
    ByteBuilder padded;
    padded.text(header("binary_little_endian", "element vertex 1\n" + kXyzFloat))
        .put(1.0f)
        .put(2.0f)
        .put(3.0f);
    padded.text(std::string("\n\0\0", 3));
    auto r = loadPoints(write("padded.ply", padded.str()));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 1u);
}

TEST_F(PlyReader, PropertyDeclaredTwiceIsAnError) {
    // The last declaration used to win.
    const std::string path = write(
        "twice.ply", header("ascii", "element vertex 1\n" + kXyzFloat + "property float x\n") + "1 2 3 4\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 7: property 'x' declared twice in element vertex"));
}

TEST_F(PlyReader, ElementDeclaredTwiceIsAnError) {
    // The second vertex element was skipped: its points were never read.
    const std::string twoVertex =
        write("twovertex.ply",
              header("ascii", "element vertex 1\n" + kXyzFloat + "element vertex 1\n" + kXyzFloat) +
                  "0 0 0\n1 1 1\n");
    EXPECT_TRUE(isBadInput(loadPoints(twoVertex), twoVertex,
                           "line 7: element 'vertex' declared twice (first on line 3)"));
    const std::string twoFaces =
        write("twofaces.ply", header("ascii",
                                     "element face 0\nproperty list uchar int vertex_indices\n"
                                     "element vertex 1\n" +
                                         kXyzFloat + "element face 0\nproperty uchar flags\n") +
                                  "0 0 0\n");
    EXPECT_TRUE(isBadInput(loadPoints(twoFaces), twoFaces,
                           "line 9: element 'face' declared twice (first on line 3)"));
}

// A binary PLY of one vertex (1, 2, 3) whose element has `extra` uchar
// properties (p0, p1, ...) before x, y, z.
std::string manyProperties(size_t extra, const std::string& more = "") {
    std::string props;
    for (size_t i = 0; i < extra; ++i) props += "property uchar p" + std::to_string(i) + "\n";
    ByteBuilder b;
    b.text(header("binary_little_endian", "element vertex 1\n" + props + kXyzFloat + more));
    b.text(std::string(extra, '\0')).put(1.0f).put(2.0f).put(3.0f);
    return b.str();
}

TEST_F(PlyReader, PropertiesPerElementAreCappedAndStillOnceEach) {
    // 100,000 properties took 21 s: each name was compared with every
    // earlier one of its element. At most 65,536 per element now.
    auto r = loadPoints(write("cap.ply", manyProperties(65536 - 3)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}}));
    const std::string over = write("over.ply", manyProperties(65536 - 2));
    EXPECT_TRUE(
        isBadInput(loadPoints(over), over,
                   "line 65540: element vertex has more than 65536 properties (limit of this loader)"));
    const std::string twice = write("twice_many.ply", manyProperties(20000, "property uchar p123\n"));
    EXPECT_TRUE(
        isBadInput(loadPoints(twice), twice, "line 20007: property 'p123' declared twice in element vertex"));
}

TEST_F(PlyReader, Utf8BomBeforeTheHeader) {
    const std::string text = "\xEF\xBB\xBF" + header("ascii", "element vertex 1\n" + kXyzFloat) + "1 2 3\n";
    auto r = loadPoints(write("bom.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}}));
    ByteBuilder b;
    b.text("\xEF\xBB\xBF" + header("binary_little_endian", "element vertex 1\n" + kXyzFloat));
    b.put(1.0f).put(2.0f).put(3.0f);
    auto bin = loadPoints(write("bom_bin.ply", b.str()));
    ASSERT_TRUE(bin.ok()) << bin.error().message;
    EXPECT_EQ(*bin, (std::vector<glm::vec3>{{1, 2, 3}}));
}

TEST_F(PlyReader, CrOnlyLineEnds) {
    const std::string text =
        "ply\rformat ascii 1.0\relement vertex 2\rproperty float x\rproperty float y\rproperty float z\r"
        "end_header\r1 2 3\r4 5 6\r";
    auto r = loadPoints(write("cr.ply", text));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}, {4, 5, 6}}));
    ByteBuilder b;
    b.text(
        "ply\rformat binary_little_endian 1.0\relement vertex 1\rproperty float x\rproperty float y\r"
        "property float z\rend_header\r");
    b.put(1.0f).put(2.0f).put(0.01f);  // 0.01f has a 0x0A (LF) byte
    auto bin = loadPoints(write("cr_bin.ply", b.str()));
    ASSERT_TRUE(bin.ok()) << bin.error().message;
    EXPECT_EQ(*bin, (std::vector<glm::vec3>{{1, 2, 0.01f}}));
}

}  // namespace
}  // namespace rthdist::io::test
