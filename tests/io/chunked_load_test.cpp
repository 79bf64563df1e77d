// The parallel loaders (issue 14): a mapped file and a read one, any chunk
// size and any thread count give the same points, bit for bit, and the same
// error, naming the first bad place in the file. Tiny chunks (1 to 64
// bytes) put chunk boundaries inside every record and line, and between
// the two bytes of "\r\n" line ends.
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "io/load_tuning.hpp"
#include "io/parallel_chunks.hpp"
#include "io/text_chunks.hpp"
#include "io_test_support.hpp"
#include "las_test_support.hpp"

namespace rthdist::io::test {
namespace {

using ChunkedLoad = TempDirTest;

// The reference: read(), one chunk for the whole file, one thread, which is
// a serial parse.
Result<PointCloud> serialLoad(const std::string& path, LoadOptions options = {}) {
    options.threads = 1;
    return loadPointCloudTuned(path, options, LoadTuning{FileAccess::kRead, ~size_t(0)});
}

bool sameBits(const PointCloud& a, const PointCloud& b) {
    if (a.scalar != b.scalar || a.floats.size() != b.floats.size() || a.doubles.size() != b.doubles.size())
        return false;
    // memcmp only on non-empty arrays: an empty vector's data() may be null.
    return (a.floats.empty() ||
            std::memcmp(a.floats.data(), b.floats.data(), a.floats.size() * sizeof(glm::vec3)) == 0) &&
           (a.doubles.empty() ||
            std::memcmp(a.doubles.data(), b.doubles.data(), a.doubles.size() * sizeof(glm::dvec3)) == 0);
}

// Every access, chunk size and thread count gives what the serial reference
// gives: the same points or the same error message.
::testing::AssertionResult loadsAlike(const std::string& path, const LoadOptions& options = {}) {
    const Result<PointCloud> reference = serialLoad(path, options);
    const size_t chunkSizes[] = {0, 1, 2, 3, 5, 7, 12, 13, 24, 31, 64, 1000};
    for (FileAccess access : {FileAccess::kMap, FileAccess::kRead}) {
        for (size_t chunkBytes : chunkSizes) {
            for (unsigned threads : {1u, 2u, 3u}) {
                LoadOptions o = options;
                o.threads = threads;
                const Result<PointCloud> r = loadPointCloudTuned(path, o, LoadTuning{access, chunkBytes});
                const std::string variant = std::string(access == FileAccess::kMap ? "mapped" : "read") +
                                            ", chunks of " + std::to_string(chunkBytes) + " bytes, " +
                                            std::to_string(threads) + " threads: ";
                if (r.ok() != reference.ok()) {
                    return ::testing::AssertionFailure()
                           << variant
                           << (r.ok() ? "loads, the serial parse fails: " + reference.error().message
                                      : "fails, the serial parse loads: " + r.error().message);
                }
                if (!r.ok() && r.error().message != reference.error().message) {
                    return ::testing::AssertionFailure()
                           << variant << "'" << r.error().message << "' instead of '"
                           << reference.error().message << "'";
                }
                if (r.ok() && !sameBits(*r, *reference)) {
                    return ::testing::AssertionFailure() << variant << "other points than the serial parse";
                }
            }
        }
    }
    return ::testing::AssertionSuccess();
}

// Coordinates with varied spellings (lengths change from line to line).
glm::dvec3 pointAt(int i) { return {i * 0.5 - 3.25, -i * 1.0e-3, i * 1e5 + 0.125}; }

std::string numbers(int i) {
    char s[96];
    std::snprintf(s, sizeof s, "%.17g %.17g %.17g", pointAt(i).x, pointAt(i).y, pointAt(i).z);
    return s;
}

constexpr int kPoints = 60;

TEST_F(ChunkedLoad, XyzWithCommentsBlankLinesAndEveryLineEnd) {
    for (const std::string eol : {"\n", "\r\n", "\r"}) {
        std::string text = "\xEF\xBB\xBF# header" + eol;
        for (int i = 0; i < kPoints; ++i) {
            text += (i % 7 == 0 ? "  " + eol : "") + (i % 11 == 0 ? "// note" + eol : "") + numbers(i) +
                    (i % 3 == 0 ? " 255 0 0" : "") + eol;
        }
        const std::string path = write("p.xyz", text);
        auto r = serialLoad(path);
        ASSERT_TRUE(r.ok()) << r.error().message;
        ASSERT_EQ(r->doubles.size(), size_t(kPoints));
        for (int i = 0; i < kPoints; ++i) EXPECT_EQ(r->doubles[size_t(i)], pointAt(i)) << i;
        EXPECT_TRUE(loadsAlike(path));
    }
}

// Text with two bad lines: every variant names the first.
TEST_F(ChunkedLoad, TextErrorInALaterChunkNamesTheFirstBadLine) {
    std::string text;
    for (int i = 0; i < kPoints; ++i) text += (i == 40 ? "1 2 x" : i == 55 ? "1 2" : numbers(i)) + "\r\n";
    const std::string path = write("bad.xyz", text);
    EXPECT_TRUE(isBadInput(serialLoad(path), path, "line 41: 'x' is not a number"));
    EXPECT_TRUE(loadsAlike(path));
    // Only the later error left: its line is counted through every chunk before it.
    text.replace(text.find("1 2 x"), 5, "1 2 3");
    const std::string later = write("later.xyz", text);
    EXPECT_TRUE(isBadInput(serialLoad(later), later, "line 56: expected 'x y z', found 2 column(s)"));
    EXPECT_TRUE(loadsAlike(later));
}

TEST_F(ChunkedLoad, ObjVerticesAmongOtherLines) {
    std::string text = "# obj\r\nmtllib m.mtl\r\n";
    for (int i = 0; i < kPoints; ++i)
        text += "v " + numbers(i) + "\r\nvn 0 0 1\r\n" + (i % 5 ? "" : "f 1 2 3\r\n");
    const std::string path = write("p.obj", text);
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->doubles.size(), size_t(kPoints));
    EXPECT_EQ(r->doubles.back(), pointAt(kPoints - 1));
    EXPECT_TRUE(loadsAlike(path));
    text.insert(text.find("v " + numbers(33)), "v 1 2\r\n");
    const std::string bad = write("bad.obj", text);
    EXPECT_TRUE(isBadInput(serialLoad(bad), bad, "vertex line with 2 coordinate(s)"));
    EXPECT_TRUE(loadsAlike(bad));
}

TEST_F(ChunkedLoad, OffVerticesStopAtTheCountAndFacesAreChecked) {
    std::string text = "OFF\n# c\n" + std::to_string(kPoints) + " 2 0\n";
    for (int i = 0; i < kPoints; ++i) text += numbers(i) + (i % 4 == 0 ? " # comment\n\n" : "\n");
    // The faces are checked (a vertex line past the count would read as one)
    // but not kept: a bad one is refused, loading points or not.
    const std::string badFaces = write("badf.off", text + "3 0 1 2\n3 a b c\n");
    EXPECT_TRUE(isBadInput(serialLoad(badFaces), badFaces, "line 80: face 1: 'a' is not a vertex index"));
    const std::string extra = write("extra.off", text + "3 0 1 2\n3 1 2 3\n4 5 6\n");
    EXPECT_TRUE(
        isBadInput(serialLoad(extra), extra, "line 81: a line after the header's 60 vertices and 2 faces"));
    text += "3 0 1 2\n3 1 2 3\n";
    const std::string path = write("p.off", text);
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->doubles.size(), size_t(kPoints));
    EXPECT_EQ(r->doubles.back(), pointAt(kPoints - 1));
    EXPECT_TRUE(loadsAlike(path));
    // Fewer vertex lines than declared: the error names the file's last line.
    std::string few = "OFF\n" + std::to_string(kPoints) + " 0 0\n";
    for (int i = 0; i < kPoints / 2; ++i) few += numbers(i) + "\n";
    few += "\n# end\n";
    const std::string fewPath = write("few.off", few);
    EXPECT_TRUE(isBadInput(serialLoad(fewPath), fewPath, "line 34: file ends at vertex 30 of 60"));
    EXPECT_TRUE(loadsAlike(fewPath));
}

TEST_F(ChunkedLoad, AsciiPlyElementsAroundTheVertices) {
    std::string text =
        "ply\r\nformat ascii 1.0\r\nelement material 2\r\nproperty uchar r\r\nelement vertex " +
        std::to_string(kPoints) +
        "\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nproperty list uchar int n\r\n"
        "element face 3\r\nproperty list uchar int vertex_indices\r\nend_header\r\n1\r\n\r\n2\r\n";
    for (int i = 0; i < kPoints; ++i) text += numbers(i) + (i % 2 ? " 0" : " 2 7 8") + "\r\n";
    text += "3 0 1 2\r\n4 0 1 2 3\r\n\r\n3 1 2 3\r\n";
    const std::string path = write("p.ply", text);
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->doubles.size(), size_t(kPoints));
    EXPECT_EQ(r->doubles[17], pointAt(17));
    EXPECT_TRUE(loadsAlike(path));
    // A face with a value too many (later) and a vertex with a bad list length (earlier).
    std::string bad = text;
    bad.replace(bad.find("4 0 1 2 3"), 9, "4 0 1 2 3 9");
    const std::string badFace = write("face.ply", bad);
    EXPECT_TRUE(isBadInput(serialLoad(badFace), badFace, "line 77: element face item 1: more values"));
    EXPECT_TRUE(loadsAlike(badFace));
    bad.replace(bad.find(numbers(50) + " 2 7 8"), numbers(50).size() + 6, numbers(50) + " z 7 8");
    const std::string badVertex = write("vertex.ply", bad);
    EXPECT_TRUE(
        isBadInput(serialLoad(badVertex), badVertex, "line 66: element vertex item 50: bad list length"));
    EXPECT_TRUE(loadsAlike(badVertex));
    // One line after the last element.
    const std::string extra = write("extra.ply", text + "5 5 5\r\n");
    EXPECT_TRUE(isBadInput(serialLoad(extra), extra, "line 80: text after the last declared element"));
    EXPECT_TRUE(loadsAlike(extra));
}

TEST_F(ChunkedLoad, AsciiPcdRowsAndTheirErrors) {
    const std::string head = "FIELDS rgb x y z\nSIZE 4 8 8 8\nTYPE U F F F\nCOUNT 1 1 1 1\nPOINTS " +
                             std::to_string(kPoints) + "\nDATA ascii\n";
    std::string rows;
    for (int i = 0; i < kPoints; ++i) rows += std::to_string(i) + " " + numbers(i) + (i % 9 ? "\n" : "\n\n");
    // A row past POINTS (trailing text counts) would be a point dropped unseen: refused.
    const std::string extra = write("x.pcd", head + rows + "trailing text\n");
    EXPECT_TRUE(
        isBadInput(serialLoad(extra), extra, "line 6: the header declares 60 points but 61 rows follow"));
    const std::string path = write("p.pcd", head + rows + "\n\n");
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->doubles.size(), size_t(kPoints));
    EXPECT_EQ(r->doubles[59], pointAt(59));
    EXPECT_TRUE(loadsAlike(path));
    const std::string cut = write("cut.pcd", head + rows.substr(0, rows.find("\n44 ") + 1));
    EXPECT_TRUE(isBadInput(serialLoad(cut), cut, "line 56: file ends at point 44 of 60"));
    EXPECT_TRUE(loadsAlike(cut));
    std::string badRows = rows;
    const size_t row52 = badRows.find("\n52 ") + 1;
    badRows.replace(row52, badRows.find('\n', row52) - row52, "52 1 2");
    const std::string bad = write("bad.pcd", head + badRows);
    EXPECT_TRUE(isBadInput(serialLoad(bad), bad, "line 65: row has 3 values, fields need 4"));
    EXPECT_TRUE(loadsAlike(bad));
}

// pointAt(i) as a T: integers get the coordinates modulo 1000, truncated.
template <class T>
T stored(double v) {
    return std::is_integral_v<T> ? static_cast<T>(std::fmod(v, 1000.0)) : static_cast<T>(v);
}

// A binary PLY of n vertices: x/y/z of type T between extra properties, in
// either byte order, with a face element after it.
template <class T>
std::string binaryPly(bool bigEndian, const std::string& type, int n) {
    ByteBuilder b(bigEndian);
    b.text(std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
           " 1.0\nelement vertex " + std::to_string(n) + "\nproperty uchar q\nproperty " + type +
           " x\nproperty short s\nproperty " + type + " y\nproperty " + type +
           " z\nproperty double w\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n");
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 p = pointAt(i);
        b.put<uint8_t>(7).put(stored<T>(p.x));
        b.put<int16_t>(-1).put(stored<T>(p.y)).put(stored<T>(p.z)).put(1.5);
    }
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    b.put<uint8_t>(1).put<int32_t>(0);
    return b.str();
}

TEST_F(ChunkedLoad, BinaryPlyEveryTypeAndByteOrder) {
    for (bool big : {false, true}) {
        const std::string suffix = big ? "_be.ply" : "_le.ply";
        const std::string f = write("f" + suffix, binaryPly<float>(big, "float", kPoints));
        const std::string d = write("d" + suffix, binaryPly<double>(big, "double", kPoints));
        const std::string i = write("i" + suffix, binaryPly<int32_t>(big, "int", kPoints));
        const std::string s = write("s" + suffix, binaryPly<int16_t>(big, "short", kPoints));
        for (const std::string& path : {f, d, i, s}) EXPECT_TRUE(loadsAlike(path)) << path;
        auto rf = serialLoad(f);
        ASSERT_TRUE(rf.ok()) << rf.error().message;
        EXPECT_EQ(rf->floats[9], glm::vec3(pointAt(9)));
        auto rd = serialLoad(d);
        ASSERT_TRUE(rd.ok()) << rd.error().message;
        EXPECT_EQ(rd->doubles[59], pointAt(59));
        auto ri = serialLoad(i);
        ASSERT_TRUE(ri.ok()) << ri.error().message;
        const glm::dvec3 p = pointAt(59);
        EXPECT_EQ(ri->doubles[59],
                  glm::dvec3(stored<int32_t>(p.x), stored<int32_t>(p.y), stored<int32_t>(p.z)));
        auto rs = serialLoad(s);
        ASSERT_TRUE(rs.ok()) << rs.error().message;
        EXPECT_EQ(rs->floats[59],
                  glm::vec3(stored<int16_t>(p.x), stored<int16_t>(p.y), stored<int16_t>(p.z)));
    }
}

TEST_F(ChunkedLoad, BinaryPlyMixedTypesAndListsInTheVertex) {
    ByteBuilder b;
    b.text(
        "ply\nformat binary_little_endian 1.0\nelement vertex 40\nproperty float x\nproperty double y\n"
        "property list uchar float n\nproperty int z\nend_header\n");
    for (int i = 0; i < 40; ++i) {
        b.put(static_cast<float>(pointAt(i).x)).put(pointAt(i).y).put<uint8_t>(uint8_t(i % 3));
        for (int k = 0; k < i % 3; ++k) b.put(1.0f);
        b.put<int32_t>(i);
    }
    const std::string path = write("lists.ply", b.str());
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->doubles[39], glm::dvec3(static_cast<float>(pointAt(39).x), pointAt(39).y, 39));
    EXPECT_TRUE(loadsAlike(path));
    // Mixed types without lists: the per-value path of the record conversion.
    ByteBuilder m(true);
    m.text(
        "ply\nformat binary_big_endian 1.0\nelement vertex 40\nproperty float x\nproperty double y\n"
        "property short z\nend_header\n");
    for (int i = 0; i < 40; ++i) m.put(static_cast<float>(pointAt(i).x)).put(pointAt(i).y).put<int16_t>(-i);
    const std::string mixed = write("mixed.ply", m.str());
    auto rm = serialLoad(mixed);
    ASSERT_TRUE(rm.ok()) << rm.error().message;
    EXPECT_EQ(rm->doubles[39], glm::dvec3(static_cast<float>(pointAt(39).x), pointAt(39).y, -39));
    EXPECT_TRUE(loadsAlike(mixed));
}

TEST_F(ChunkedLoad, BinaryPlyErrorsAfterTheVertices) {
    std::string bytes = binaryPly<float>(false, "float", kPoints);
    const std::string cut = write("cut.ply", bytes.substr(0, bytes.size() - 3));
    EXPECT_TRUE(isBadInput(serialLoad(cut), cut, "element face item 1: file ends inside the item"));
    EXPECT_TRUE(loadsAlike(cut));
    const std::string extra = write("extra.ply", bytes + "junk");
    EXPECT_TRUE(isBadInput(serialLoad(extra), extra, "4 bytes follow the last declared element"));
    EXPECT_TRUE(loadsAlike(extra));
    // A NaN in a late vertex and an infinity in a later one: the first is named.
    std::string nan = bytes;
    const size_t vertexBytes = 1 + 4 + 2 + 4 + 4 + 8;
    const size_t body = nan.find("end_header\n") + 11;
    const float nanValue = std::nanf("");
    const float infValue = INFINITY;
    std::memcpy(&nan[body + 47 * vertexBytes + 7], &nanValue, 4);  // y of vertex 47
    std::memcpy(&nan[body + 53 * vertexBytes + 1], &infValue, 4);  // x of vertex 53
    const std::string nanPath = write("nan.ply", nan);
    EXPECT_TRUE(isBadInput(serialLoad(nanPath), nanPath, "vertex 47: coordinate y is NaN"));
    EXPECT_TRUE(loadsAlike(nanPath));
    // The vertices are checked as they are converted, but the body's
    // structure is reported first, as when the check was a pass of its own.
    const std::string nanAndJunk = write("nan_junk.ply", nan + "junk");
    EXPECT_TRUE(isBadInput(serialLoad(nanAndJunk), nanAndJunk, "4 bytes follow the last declared element"));
    EXPECT_TRUE(loadsAlike(nanAndJunk));
    const std::string nanAndCut = write("nan_cut.ply", nan.substr(0, nan.size() - 3));
    EXPECT_TRUE(
        isBadInput(serialLoad(nanAndCut), nanAndCut, "element face item 1: file ends inside the item"));
    EXPECT_TRUE(loadsAlike(nanAndCut));
}

// Enough points that the cloud is mapped on its own (PointAllocator: 4 MiB
// and more) and every thread converts chunks of its own: the same points as
// the serial parse, and the first of two bad vertices named, with the
// default chunks and with page-sized ones.
TEST_F(ChunkedLoad, LargeBinaryPlyAndPcdOnSeveralThreads) {
    constexpr int kLarge = 400'000;  // 4.8 MB of float points, 9.6 MB of doubles
    ByteBuilder f(false);
    f.text("ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(kLarge) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nend_header\n");
    ByteBuilder d(true);
    d.text("ply\nformat binary_big_endian 1.0\nelement vertex " + std::to_string(kLarge) +
           "\nproperty double x\nproperty double y\nproperty double z\nend_header\n");
    ByteBuilder c(false);
    c.text("VERSION .7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nPOINTS " +
           std::to_string(kLarge) + "\nDATA binary\n");
    for (int i = 0; i < kLarge; ++i) {
        const glm::dvec3 p = pointAt(i);
        f.put(float(p.x)).put(float(p.y)).put(float(p.z)).put<uint8_t>(uint8_t(i));
        d.put(p.x).put(p.y).put(p.z);
        c.put(float(p.x)).put(float(p.y)).put(float(p.z)).put<uint32_t>(uint32_t(i));
    }
    const std::string paths[] = {write("large_f.ply", f.str()), write("large_d.ply", d.str()),
                                 write("large.pcd", c.str())};
    for (const std::string& path : paths) {
        const Result<PointCloud> reference = serialLoad(path);
        ASSERT_TRUE(reference.ok()) << reference.error().message;
        ASSERT_EQ(reference->size(), size_t(kLarge));
        const glm::dvec3 last = pointAt(kLarge - 1);
        if (reference->scalar == Scalar::kFloat64) {
            EXPECT_EQ(reference->doubles.back(), last) << path;
        } else {
            EXPECT_EQ(reference->floats.back(), glm::vec3(float(last.x), float(last.y), float(last.z)))
                << path;
        }
        for (size_t chunkBytes : {size_t(0), size_t(4096)}) {
            for (unsigned threads : {2u, 3u}) {
                LoadOptions o;
                o.threads = threads;
                const Result<PointCloud> r =
                    loadPointCloudTuned(path, o, LoadTuning{FileAccess::kMap, chunkBytes});
                ASSERT_TRUE(r.ok()) << r.error().message;
                EXPECT_TRUE(sameBits(*r, *reference)) << path << ", " << threads << " threads";
            }
        }
    }
    // An infinity late in the file and a NaN later still: the infinity is named.
    std::string bad = f.str();
    const size_t body = bad.find("end_header\n") + 11;
    const float inf = -INFINITY, nan = std::nanf("");
    std::memcpy(&bad[body + 390'001 * 13 + 8], &inf, 4);  // z of vertex 390001
    std::memcpy(&bad[body + 399'000 * 13 + 0], &nan, 4);  // x of vertex 399000
    const std::string badPath = write("large_bad.ply", bad);
    for (unsigned threads : {1u, 2u, 3u}) {
        LoadOptions o;
        o.threads = threads;
        EXPECT_TRUE(isBadInput(loadPointCloud(badPath, o), badPath,
                               "vertex 390001: coordinate z is infinite (or beyond float range)"));
    }
}

TEST_F(ChunkedLoad, BinaryPcd) {
    ByteBuilder b;
    b.text(
        "VERSION .7\nFIELDS rgb x y z\nSIZE 4 8 8 8\nTYPE U F F F\nCOUNT 1 1 1 1\nPOINTS 50\nDATA binary\n");
    for (int i = 0; i < 50; ++i)
        b.put<uint32_t>(uint32_t(i)).put(pointAt(i).x).put(pointAt(i).y).put(pointAt(i).z);
    const std::string path = write("b.pcd", b.str());
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->doubles[49], pointAt(49));
    EXPECT_TRUE(loadsAlike(path));
    const std::string cut = write("cut.pcd", b.str().substr(0, b.str().size() - 1));
    EXPECT_TRUE(isBadInput(serialLoad(cut), cut, "declares 50 points of 28 bytes"));
    EXPECT_TRUE(loadsAlike(cut));
    // Rows checked as they are converted: the first non-finite one is named.
    std::string nan = b.str();
    const size_t body = nan.find("DATA binary\n") + 12;
    const double nanValue = std::nan(""), infValue = INFINITY;
    std::memcpy(&nan[body + 31 * 28 + 20], &infValue, 8);  // z of point 31
    std::memcpy(&nan[body + 44 * 28 + 4], &nanValue, 8);   // x of point 44
    const std::string nanPath = write("nan.pcd", nan);
    EXPECT_TRUE(isBadInput(serialLoad(nanPath), nanPath, "vertex 31: coordinate z is infinite"));
    EXPECT_TRUE(loadsAlike(nanPath));
}

LasSpec lasSpec(int minor, int format, int n) {
    LasSpec s;
    s.minor = minor;
    s.format = format;
    s.extraBytes = 3;
    s.scale = {0.001, 0.01, 0.1};
    s.offset = {500000.0, 5400000.0, -20.0};
    for (int i = 0; i < n; ++i) {
        s.points.push_back(LasPoint{{i * 1000 - 7, -i * 33, i * i}, static_cast<uint8_t>(1 + i % 3 * 2)});
    }
    return s;
}

TEST_F(ChunkedLoad, LasEveryFormatWithAndWithoutTheClassFilter) {
    for (int format = 0; format <= 10; ++format) {
        const LasSpec spec = lasSpec(format >= 6 ? 4 : 2, format, 45);
        const std::string path = write("p" + std::to_string(format) + ".las", lasBytes(spec));
        auto r = serialLoad(path);
        ASSERT_TRUE(r.ok()) << r.error().message;
        ASSERT_EQ(r->doubles.size(), 45u);
        EXPECT_EQ(r->doubles[44], lasCoordinates(spec, spec.points[44])) << format;
        EXPECT_TRUE(loadsAlike(path)) << format;
        LoadOptions ground;
        ground.lasClasses = {3, 5};  // classes are 1, 3, 5 in turn
        auto g = serialLoad(path, ground);
        ASSERT_TRUE(g.ok()) << g.error().message;
        ASSERT_EQ(g->doubles.size(), 30u);
        EXPECT_EQ(g->doubles[29], lasCoordinates(spec, spec.points[44])) << format;
        EXPECT_TRUE(loadsAlike(path, ground)) << format;
        LoadOptions none;
        none.lasClasses = {2};
        EXPECT_TRUE(isBadInput(serialLoad(path, none), path, "(the file holds class 1, 3, 5)"));
        EXPECT_TRUE(loadsAlike(path, none)) << format;
    }
}

TEST_F(ChunkedLoad, LasNonFiniteCoordinateNamesTheFirstPoint) {
    LasSpec spec = lasSpec(2, 1, 40);
    spec.scale = {1e300, 1.0, 1.0};  // X * scale overflows where |X| > 1.8e8
    for (LasPoint& p : spec.points) p.xyz[0] = 1;
    spec.points[31].xyz[0] = 1'000'000'000;
    spec.points[36].xyz[0] = -1'000'000'000;
    const std::string path = write("inf.las", lasBytes(spec));
    // Records of 31 bytes (format 1 and 3 extra bytes) after the 227-byte header.
    EXPECT_TRUE(isBadInput(serialLoad(path), path, "point 31 (byte offset 1188): X * scale + offset"));
    EXPECT_TRUE(loadsAlike(path));
}

TEST_F(ChunkedLoad, GzippedFilesAreReadAndChunkedAlike) {
    std::string text;
    for (int i = 0; i < kPoints; ++i) text += numbers(i) + "\n";
    const std::string path = write("p.xyz.gz", gzip(text));
    auto r = serialLoad(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->doubles.size(), size_t(kPoints));
    EXPECT_TRUE(loadsAlike(path));
    EXPECT_TRUE(loadsAlike(write("b.ply.gz", gzip(binaryPly<double>(true, "double", kPoints)))));
}

// Formats without chunks still go through the mapping.
TEST_F(ChunkedLoad, StlAndGlbMappedAsRead) {
    ByteBuilder stl;
    stl.text(std::string(80, ' ')).put<uint32_t>(2);
    for (int facet = 0; facet < 2; ++facet) {
        stl.put(0.0f).put(0.0f).put(1.0f);
        for (const glm::vec3& p : threePoints()) stl.put(p.x + facet).put(p.y).put(p.z);
        stl.put<uint16_t>(0);
    }
    const std::string binary = write("b.stl", stl.str());
    auto r = serialLoad(binary);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->floats.size(), 6u);
    EXPECT_TRUE(loadsAlike(binary));
    EXPECT_TRUE(loadsAlike(write("a.stl",
                                 "solid t\r\nfacet normal 0 0 1\r\nouter loop\r\nvertex 1 2 3\r\nvertex 4 5 "
                                 "6\r\nvertex 7 8 9\r\nendloop\r\nendfacet\r\nendsolid t\r\n")));
    ByteBuilder bin;
    for (const glm::vec3& p : threePoints()) bin.put(p.x).put(p.y).put(p.z);
    const std::string json =
        R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36}],"bufferViews":[{"buffer":0,)"
        R"("byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],)"
        R"("scenes":[{"nodes":[0]}],"scene":0})";
    const std::string glbPath = write("a.glb", glb(json, bin.str()));
    auto g = serialLoad(glbPath);
    ASSERT_TRUE(g.ok()) << g.error().message;
    EXPECT_EQ(std::vector<glm::vec3>(g->floats.begin(), g->floats.end()), threePoints());
    EXPECT_TRUE(loadsAlike(glbPath));
}

TEST_F(ChunkedLoad, AFifoIsRefusedWithoutBlocking) {
    const std::string path = file("pipe.xyz");
    ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "open: not a regular file"));
}

// ---- the helpers themselves ------------------------------------------------

TEST(ParallelChunks, TheLowestFailedChunkWinsWhateverTheThreads) {
    for (unsigned threads : {1u, 2u, 4u}) {
        auto err = forEachChunk(100, ChunkPlan{threads, 1}, [](size_t c) -> std::optional<Error> {
            if (c == 71 || c == 23 || c == 90) return Error{ErrorCode::kBadInput, std::to_string(c)};
            return std::nullopt;
        });
        ASSERT_TRUE(err.has_value());
        EXPECT_EQ(err->message, "23") << threads;
    }
}

TEST(ParallelChunks, AnExceptionReachesTheCaller) {
    auto throwing = [] {
        (void)forEachChunk(50, ChunkPlan{3, 1}, [](size_t c) -> std::optional<Error> {
            if (c == 17) throw std::runtime_error("chunk 17");
            return std::nullopt;
        });
    };
    EXPECT_THROW(throwing(), std::runtime_error);
    EXPECT_EQ(chunkCount(0, 5), 0u);
    EXPECT_EQ(chunkCount(10, 5), 2u);
    EXPECT_EQ(chunkCount(11, 5), 3u);
    EXPECT_EQ(chunkCount(~uint64_t(0), ~uint64_t(0)), 1u);
}

bool isAnyLine(std::string_view) { return true; }

TEST(TextChunks, ChunksNeverSplitACrLfAndCountLines) {
    const std::string text = "a\r\nbb\r\rc\n\r\nd";  // lines: a, bb, "", c, "", d
    for (size_t bytes = 1; bytes <= text.size() + 1; ++bytes) {
        const TextChunks chunks = splitLines(text, 10, &isAnyLine, ChunkPlan{2, bytes});
        EXPECT_EQ(chunks.lines, 6u) << bytes;
        EXPECT_EQ(chunks.lastLine(), 15u) << bytes;
        size_t expectBegin = 0;
        for (const TextChunk& c : chunks.chunks) {
            EXPECT_EQ(c.begin, expectBegin) << bytes;
            EXPECT_FALSE(c.begin > 0 && text[c.begin - 1] == '\r' && text[c.begin] == '\n') << bytes;
            expectBegin = c.end;
        }
        EXPECT_EQ(expectBegin, text.size());
    }
}

TEST(TextChunks, KeepItemsCutsAfterTheLastKeptLine) {
    const std::string text = "1\n\n2\n3\n\n4\n";
    auto nonBlank = [](std::string_view line) { return !trimBlank(line).empty(); };
    for (size_t bytes : {size_t(1), size_t(3), size_t(100)}) {
        TextChunks chunks = splitLines(text, 1, +nonBlank, ChunkPlan{1, bytes});
        keepItems(chunks, text, +nonBlank, 3);
        ASSERT_FALSE(chunks.chunks.empty());
        EXPECT_EQ(chunks.chunks.back().end, text.find("3\n") + 2) << bytes;
        EXPECT_EQ(chunks.items, 4u);  // the whole text's count stays
    }
}

}  // namespace
}  // namespace rthdist::io::test
