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
    const std::string path = write("points.las", "1 2 3\n");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "unsupported extension '.las'"));
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

}  // namespace
}  // namespace rthdist::io::test
