// core::scanPackedFloats (src/core/packed_float_scan.hpp) against the point
// by point loop: every count from 0 to 13 (the four-point steps and every
// remainder), unaligned starts, points outside the test box on each axis
// and in each of the four lanes' positions, and non-finite coordinates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/input_frame.hpp"
#include "core/packed_float_scan.hpp"
#include "rthdist/point_view.hpp"

namespace rthdist::core {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

PackedScan bruteForce(const float* xyz, size_t count, const glm::vec3& lo, const glm::vec3& hi) {
    PackedScan s;
    for (size_t i = 0; i < count; ++i)
        for (int axis = 0; axis < 3; ++axis) {
            const float v = xyz[3 * i + axis];
            if (std::isfinite(v) || std::isinf(v)) {
                s.box.lo[axis] = std::min(s.box.lo[axis], v);
                s.box.hi[axis] = std::max(s.box.hi[axis], v);
            }
            s.outside = s.outside || v < lo[axis] || v > hi[axis];
            s.nonFinite = s.nonFinite || !std::isfinite(v);
        }
    return s;
}

void expectSame(const PackedScan& got, const PackedScan& want) {
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(got.box.lo[axis], want.box.lo[axis]) << "axis " << axis;
        EXPECT_EQ(got.box.hi[axis], want.box.hi[axis]) << "axis " << axis;
    }
    EXPECT_EQ(got.outside, want.outside);
    EXPECT_EQ(got.nonFinite, want.nonFinite);
}

TEST(PackedFloatScan, EqualsThePointByPointLoopAtEveryCountAndOffset) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float> storage(3 * 20 + 1);
    // A different bound on each axis: a coordinate just past its own axis's
    // bound lies within another axis's, so a test against the wrong axis misses it.
    const glm::vec3 lo(-0.99f, -0.95f, -0.9f), hi(0.99f, 0.95f, 0.9f);
    for (size_t offset = 0; offset < 2; ++offset)  // 4-byte and 8-byte aligned starts
        for (size_t count = 0; count <= 13; ++count)
            for (int trial = 0; trial < 20; ++trial) {
                for (float& v : storage) v = u(rng) * 0.8f;  // inside the test box
                float* xyz = storage.data() + offset;
                if (count > 0 && trial % 2 == 1) {  // one coordinate outside, anywhere
                    const size_t at = size_t(rng()) % (3 * count);
                    const int axis = int(at % 3);
                    xyz[at] = trial % 4 == 1 ? hi[axis] + 0.01f : lo[axis] - 0.01f;
                }
                SCOPED_TRACE("offset " + std::to_string(offset) + " count " + std::to_string(count) +
                             " trial " + std::to_string(trial));
                expectSame(scanPackedFloats(xyz, count, lo, hi), bruteForce(xyz, count, lo, hi));
                // No test box: never outside.
                EXPECT_FALSE(scanPackedFloats(xyz, count, glm::vec3(-kInf), glm::vec3(kInf)).outside);
            }
}

TEST(PackedFloatScan, NonFiniteCoordinatesAreReportedInEveryPosition) {
    for (size_t count : {1u, 4u, 5u, 8u, 11u})
        for (size_t at = 0; at < 3 * count; ++at)
            for (float bad : {std::numeric_limits<float>::quiet_NaN(), kInf, -kInf}) {
                std::vector<float> xyz(3 * count, 0.25f);
                xyz[at] = bad;
                const PackedScan s = scanPackedFloats(xyz.data(), count, glm::vec3(-kInf), glm::vec3(kInf));
                EXPECT_TRUE(s.nonFinite) << "count " << count << " at " << at << " value " << bad;
            }
}

// summarizeSet takes the packed path for packed floats: the same box, and
// the first bad point still named.
TEST(PackedFloatScan, SummarizeSetKeepsItsBoxAndFirstBadPoint) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-5.0f, 5.0f);
    std::vector<float> xyz(3 * 100003);
    for (float& v : xyz) v = u(rng);
    Result<SetSummary> s = summarizeSet(PointView::floats(xyz.data(), 100003), "A", 2);
    ASSERT_TRUE(s);
    const PackedScan want = bruteForce(xyz.data(), 100003, glm::vec3(-kInf), glm::vec3(kInf));
    EXPECT_EQ(s->box.lo, glm::dvec3(want.box.lo));
    EXPECT_EQ(s->box.hi, glm::dvec3(want.box.hi));
    xyz[3 * 70001 + 2] = std::numeric_limits<float>::quiet_NaN();
    xyz[3 * 90001] = kInf;
    Result<SetSummary> bad = summarizeSet(PointView::floats(xyz.data(), 100003), "A", 2);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("point 70001 "), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace rthdist::core
