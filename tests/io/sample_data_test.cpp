// The shipped sample (repo data/, see data/README.md): the Stanford Bunny and
// its res2 decimation, binary little-endian PLY converted from Stanford's
// ascii originals. These run everywhere, CI included.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

const std::string kDataDir = RTHDIST_SAMPLE_DATA_DIR;

TEST(SampleData, BunnyLoads) {
    auto r = loadPoints(kDataDir + "/bunny.ply");
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 35947u);
    // First and last vertex as printed in bun_zipper.ply.
    EXPECT_EQ(r->front(), glm::vec3(-0.0378297f, 0.12794f, 0.00447467f));
    EXPECT_EQ(r->back(), glm::vec3(-0.0400442f, 0.15362f, -0.00816685f));
}

TEST(SampleData, BunnyRes2Loads) {
    auto r = loadPoints(kDataDir + "/bunny_res2.ply");
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 8171u);
}

TEST(SampleData, BunnyBoundingBox) {
    auto r = loadPoints(kDataDir + "/bunny.ply");
    ASSERT_TRUE(r.ok()) << r.error().message;
    glm::vec3 lo(1e30f);
    glm::vec3 hi(-1e30f);
    for (const glm::vec3& p : *r) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    // The bunny is about 0.16 x 0.15 x 0.12 (metres) around the origin.
    EXPECT_NEAR(hi.x - lo.x, 0.155, 0.01);
    EXPECT_NEAR(hi.y - lo.y, 0.152, 0.01);
    EXPECT_NEAR(hi.z - lo.z, 0.121, 0.01);
}

}  // namespace
}  // namespace rthdist::io::test
