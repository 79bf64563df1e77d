// readFileBytes and the loadPoints front door: missing files, directories,
// empty files, extensions, gzip.
#include "io/file_bytes.hpp"

#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using FileBytes = TempDirTest;

TEST_F(FileBytes, MissingFileIsBadInput) {
    const std::string path = file("nope.ply");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "open"));
    EXPECT_TRUE(isBadInput(readFileBytes(path), path, "No such file"));
}

TEST_F(FileBytes, DirectoryIsBadInput) {
    const std::string path = file("dir.ply");
    std::filesystem::create_directory(path);
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "directory"));
}

TEST_F(FileBytes, EmptyFileIsBadInput) {
    const std::string path = write("empty.ply", "");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "empty file"));
}

TEST_F(FileBytes, EmptyGzipIsBadInput) {
    const std::string path = write("empty.xyz.gz", gzip(""));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "empty file"));
}

TEST_F(FileBytes, UnsupportedExtensionIsBadInput) {
    const std::string path = write("points.e57", "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "unsupported extension '.e57'"));
}

TEST_F(FileBytes, ExtensionIsCaseInsensitive) {
    const std::string path = write("POINTS.XYZ", "1 2 3\n");
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 1u);
}

TEST_F(FileBytes, GzipRoundTrip) {
    std::string raw;
    for (int i = 0; i < 20000; ++i) raw += std::to_string(i) + " " + std::to_string(-i) + " 0.5\n";
    const std::string path = write("many.xyz.gz", gzip(raw));
    auto bytes = readFileBytes(path);
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    EXPECT_EQ(*bytes, raw);
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 20000u);
    EXPECT_EQ((*r)[19999], glm::vec3(19999.0f, -19999.0f, 0.5f));
}

TEST_F(FileBytes, ConcatenatedGzipMembers) {
    const std::string path = write("two.xyz.gz", gzip("1 2 3\n") + gzip("4 5 6\n"));
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 2u);
    EXPECT_EQ((*r)[1], glm::vec3(4, 5, 6));
}

TEST_F(FileBytes, TruncatedGzipIsBadInput) {
    std::string raw;
    for (int i = 0; i < 5000; ++i) raw += "1 2 3\n";
    const std::string gz = gzip(raw);
    const std::string path = write("cut.xyz.gz", gz.substr(0, gz.size() / 2));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "truncated gzip"));
}

TEST_F(FileBytes, GzipWithoutTrailerIsBadInput) {
    const std::string gz = gzip("1 2 3\n");
    const std::string path = write("notrailer.xyz.gz", gz.substr(0, gz.size() - 8));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "truncated gzip"));
}

TEST_F(FileBytes, GzipWithAWrongSizeInItsTrailerIsBadInput) {
    // The trailer's size (ISIZE) sizes the one-call inflate; one that lies
    // is refused by the size check, whichever path reads the stream.
    std::string raw;
    for (int i = 0; i < 5000; ++i) raw += "1 2 3\n";
    for (const int delta : {-1, 1}) {
        std::string gz = gzip(raw);
        gz[gz.size() - 4] = static_cast<char>(gz[gz.size() - 4] + delta);
        const std::string path = write("size.xyz.gz", gz);
        EXPECT_TRUE(isBadInput(loadPoints(path), path, "corrupt gzip stream")) << delta;
    }
}

TEST_F(FileBytes, GzipWithZeroPaddingAfterItsMemberLoads) {
    std::string raw;
    for (int i = 0; i < 5000; ++i) raw += "1 2 3\n";
    const std::string path = write("pad.xyz.gz", gzip(raw) + std::string(100, '\0'));
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 5000u);
    // Anything else after it is a second member, or corrupt.
    const std::string junk = write("junk.xyz.gz", gzip(raw) + "xyz");
    EXPECT_FALSE(loadPoints(junk).ok());
}

TEST_F(FileBytes, NotGzipIsBadInput) {
    const std::string path = write("plain.xyz.gz", "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset 0"));
}

TEST_F(FileBytes, CorruptGzipIsBadInput) {
    std::string gz = gzip(std::string(4000, 'a'));
    for (size_t i = 12; i < gz.size() - 8; ++i) gz[i] = static_cast<char>(gz[i] ^ 0x5a);
    const std::string path = write("corrupt.xyz.gz", gz);
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset"));
}

// ---- hardening (issue 15): decompression bombs ------------------------------

// A binary PLY of three points followed by `zeros` zero bytes, gzipped.
std::string paddedPlyGz(size_t zeros) {
    ByteBuilder b;
    b.text(
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n");
    for (const glm::vec3& p : threePoints()) b.put(p.x).put(p.y).put(p.z);
    return gzip(b.str() + std::string(zeros, '\0'));
}

TEST_F(FileBytes, GzipBeyondWhatThePlyHeaderDeclaresIsRefused) {
    // Was inflated in full (3.9 GB from 3.9 MB) before the header was looked at.
    const std::string path = write("bomb.ply.gz", paddedPlyGz(size_t{32} << 20));
    EXPECT_TRUE(isBadInput(loadPoints(path), path,
                           "gzip: inflates to more than the 65687 bytes its header accounts for"));
    // A little padding is fine.
    auto r = loadPoints(write("padded.ply.gz", paddedPlyGz(100)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(FileBytes, GzipPlyHeaderIsCheckedBeforeInflating) {
    const std::string path = write(
        "badhead.ply.gz",
        gzip("ply\nformat binary_middle_endian 1.0\nend_header\n" + std::string(size_t{64} << 20, '\0')));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "line 2: unsupported format 'binary_middle_endian'"));
}

TEST_F(FileBytes, GzipInflationRatioCap) {
    const std::string zeros = gzip(std::string(size_t{4} << 20, '0'));
    const std::string path = file("zeros.xyz.gz");
    auto capped = gunzip(zeros, path, nullptr, 1u << 20);
    EXPECT_TRUE(isBadInput(capped, path, "gzip: inflates to more than 1048576 bytes"));
    auto whole = gunzip(zeros, path, nullptr, 4u << 20);
    ASSERT_TRUE(whole.ok()) << whole.error().message;
    EXPECT_EQ(whole->size(), size_t{4} << 20);
    EXPECT_EQ(inflateCap(1000), kMinInflateCap);
    EXPECT_EQ(inflateCap(uint64_t{10} << 20), kMaxInflateRatio * (uint64_t{10} << 20));
}

TEST_F(FileBytes, GzipBeyondWhatTheGlbHeaderDeclaresIsRefused) {
    const std::string glbBytes = glb(R"({"asset":{"version":"2.0"}})", "");
    const std::string path = write("bomb.glb.gz", gzip(glbBytes + std::string(size_t{16} << 20, '\0')));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "its header accounts for"));
}

TEST_F(FileBytes, GzipBeyondWhatTheBinaryStlHeaderDeclaresIsRefused) {
    ByteBuilder b;
    b.text(std::string(80, ' ')).put<uint32_t>(1);
    b.put(0.0f).put(0.0f).put(1.0f);
    for (const glm::vec3& p : threePoints()) b.put(p.x).put(p.y).put(p.z);
    b.put<uint16_t>(0);
    const std::string path = write("bomb.stl.gz", gzip(b.str() + std::string(size_t{16} << 20, '\0')));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "its header accounts for"));
}

}  // namespace
}  // namespace rthdist::io::test
