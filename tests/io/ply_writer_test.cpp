// writePlyPoints: exact round trip through loadPoints, and write errors.
#include <limits>
#include <random>

#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using PlyWriter = TempDirTest;

TEST_F(PlyWriter, RoundTripIsBitExact) {
    constexpr unsigned kSeed = 20240611;
    std::mt19937 rng(kSeed);
    std::uniform_real_distribution<float> u(-1e6f, 1e6f);
    std::vector<glm::vec3> pts(1000);
    for (glm::vec3& p : pts) p = {u(rng), u(rng), u(rng)};
    pts[0] = {-0.0f, std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()};
    const std::string path = file("w.ply");
    auto w = writePlyPoints(path, pts);
    ASSERT_TRUE(w.ok()) << w.error().message;
    auto r = loadPoints(path);
    ASSERT_TRUE(r.ok()) << "seed " << kSeed << ": " << r.error().message;
    ASSERT_EQ(r->size(), pts.size());
    EXPECT_EQ(std::memcmp(r->data(), pts.data(), pts.size() * sizeof(glm::vec3)), 0) << "seed " << kSeed;
    EXPECT_EQ(std::filesystem::file_size(path), 1000u * 12u + 145u);
}

TEST_F(PlyWriter, UnwritablePathIsBadInput) {
    const std::string path = file("no/such/dir/w.ply");
    EXPECT_TRUE(isBadInput(writePlyPoints(path, threePoints()), path, "open"));
}

}  // namespace
}  // namespace rthdist::io::test
