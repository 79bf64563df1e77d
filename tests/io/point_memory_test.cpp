// PointAllocator (rthdist/io.hpp): resize(n) leaves new points unwritten for
// the loaders to fill, but every other way of making points writes them,
// for small arrays (operator new) and large ones (mapped on their own).
#include <gtest/gtest.h>

#include <glm/vec3.hpp>

#include <vector>

#include "rthdist/io.hpp"

namespace rthdist::io::test {
namespace {

// 1,000 points (operator new) and 1,000,000 (12 MB: mapped).
constexpr size_t kSizes[] = {1000, 1'000'000};

TEST(PointAllocator, ResizeWithAValueFillsAndCopiesAreEqual) {
    for (size_t n : kSizes) {
        PointArray<glm::vec3> a(n, glm::vec3(1.5f, -2.0f, 3.25f));
        ASSERT_EQ(a.size(), n);
        EXPECT_EQ(a.front(), glm::vec3(1.5f, -2.0f, 3.25f));
        EXPECT_EQ(a.back(), glm::vec3(1.5f, -2.0f, 3.25f));
        a.resize(2 * n, glm::vec3(0.0f));
        EXPECT_EQ(a[n - 1], glm::vec3(1.5f, -2.0f, 3.25f));
        EXPECT_EQ(a[2 * n - 1], glm::vec3(0.0f));
        const PointArray<glm::vec3> copy = a;
        EXPECT_TRUE(copy == a);
        EXPECT_EQ(std::vector<glm::vec3>(copy.begin(), copy.end()),
                  std::vector<glm::vec3>(a.begin(), a.end()));
    }
}

TEST(PointAllocator, ResizedPointsHoldWhatIsWrittenToThem) {
    for (size_t n : kSizes) {
        PointArray<glm::dvec3> a;
        a.resize(n);  // unwritten: every point is written before it is read
        for (size_t i = 0; i < n; ++i) a[i] = glm::dvec3(double(i), -double(i), 0.5);
        EXPECT_EQ(a[n / 2], glm::dvec3(double(n / 2), -double(n / 2), 0.5));
        PointArray<glm::dvec3> moved = std::move(a);
        EXPECT_EQ(moved.back(), glm::dvec3(double(n - 1), -double(n - 1), 0.5));
        moved.push_back(glm::dvec3(7.0));
        EXPECT_EQ(moved.size(), n + 1);
        EXPECT_EQ(moved[n - 1], glm::dvec3(double(n - 1), -double(n - 1), 0.5));
    }
}

}  // namespace
}  // namespace rthdist::io::test
