// Pure size and precision rules of the engine, at and around the boundaries
// where 32-bit arithmetic ends (2^28 16-byte records = 4 GiB, 2^31, 2^32),
// without a device: the scaling rule across the whole float range, the
// self-check's host halves, and the limit check.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "core/index_space.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {
namespace {

// Every float magnitude class: subnormal, tiny, ordinary, huge, near max.
const float kMagnitudes[] = {std::numeric_limits<float>::denorm_min(),
                             1.4e-45f * 7.0f,
                             1e-40f,
                             std::numeric_limits<float>::min(),
                             1e-30f,
                             0x1p-41f,
                             0x1p-40f,
                             1.0f,
                             0x1p40f,
                             0x1p41f,
                             1e30f,
                             std::numeric_limits<float>::max()};

TEST(ExactScale, IsAFinitePowerOfTwoForEveryFloatMagnitude) {
    for (float m : kMagnitudes) {
        SCOPED_TRACE(m);
        const double s = core::exactScale(double(m));
        ASSERT_TRUE(std::isfinite(s));
        ASSERT_GT(s, 0.0);
        int e = 0;
        EXPECT_EQ(std::frexp(s, &e), 0.5) << "not a power of two";
        // The scaled magnitude is a normal float in [2^-40, 2^40].
        const float scaled = float(double(m) * s);
        EXPECT_TRUE(std::isnormal(scaled));
        EXPECT_GE(scaled, 0x1p-40f);
        EXPECT_LE(scaled, 0x1p40f);
    }
}

TEST(ExactScale, LeavesOrdinaryMagnitudesAlone) {
    EXPECT_EQ(core::exactScale(0.0), 1.0);
    EXPECT_EQ(core::exactScale(1.0), 1.0);
    EXPECT_EQ(core::exactScale(0x1p-40), 1.0);
    EXPECT_EQ(core::exactScale(0x1p40), 1.0);
    EXPECT_EQ(core::exactScale(5.4e6), 1.0);
}

TEST(ExactScale, ScaledSquaredDistancesNeitherOverflowNorVanish) {
    for (float m : kMagnitudes) {
        SCOPED_TRACE(m);
        const double s = core::exactScale(double(m));
        const float a = float(double(m) * s), b = float(double(-m) * s);
        const float d = a - b;
        const float d2 = d * d + d * d + d * d;  // the largest squared distance at this magnitude
        EXPECT_TRUE(std::isfinite(d2));
        EXPECT_GT(d2, 0.0f);
    }
}

TEST(SampleSlots, CoverFirstAndLastAt32BitBoundaries) {
    for (uint32_t n :
         {1u, 2u, 31u, 32u, 33u, (1u << 28) - 1, 1u << 28, (1u << 28) + 1, 1u << 31, 0xffffffffu}) {
        SCOPED_TRACE(n);
        const std::vector<uint32_t> s = sampleSlots(n, 32);
        ASSERT_EQ(s.size(), std::min<uint32_t>(n, 32));
        EXPECT_EQ(s.front(), 0u);
        EXPECT_EQ(s.back(), n - 1);
        for (size_t k = 1; k < s.size(); ++k) EXPECT_LT(s[k - 1], s[k]);
    }
}

TEST(IndexCheck, PermutationSumAt32BitBoundaries) {
    for (uint64_t n : {uint64_t(1) << 28, (uint64_t(1) << 31) - 1, uint64_t(0xffffffff)}) {
        SCOPED_TRACE(n);
        const uint64_t sum = n % 2 == 0 ? (n / 2) * (n - 1) : n * ((n - 1) / 2);
        EXPECT_EQ(sum, n * (n - 1) / 2) << "no 64-bit overflow below 2^32 points";
        EXPECT_EQ(indexCheckFailure(n, 0, sum, sum, 1000, 1000), "");
        EXPECT_NE(indexCheckFailure(n, 0, sum - 1, sum, 1000, 1000), "") << "a lost point";
        EXPECT_NE(indexCheckFailure(n, 3, sum, sum, 1000, 1000), "") << "records off their cell";
        EXPECT_NE(indexCheckFailure(n, 0, sum, sum, 1001, 1000), "") << "cells past the buffer";
        EXPECT_NE(indexCheckFailure(n, 0, sum, sum, 0, 1000), "") << "no cell written";
    }
}

uint64_t packed(float d2, uint32_t index) { return (uint64_t(std::bit_cast<uint32_t>(d2)) << 32) | index; }

SampledQuery record(uint32_t slot, const glm::vec3& q, uint32_t qi, float d2, uint32_t ti, uint32_t status) {
    SampledQuery s;
    s.slot = slot;
    s.sorted[0] = q.x;
    s.sorted[1] = q.y;
    s.sorted[2] = q.z;
    s.sorted[3] = std::bit_cast<float>(qi);
    s.state.best = packed(d2, ti);
    s.state.status = status;
    return s;
}

struct TwoSets {
    std::vector<glm::vec3> q{{0, 0, 0}, {1, 0, 0}}, t{{0, 0, 1}, {3, 0, 0}};
};

TEST(SampledQueries, AcceptAConsistentRun) {
    TwoSets s;
    // q0 -> t0 at 1 (slot 0), q1 -> t0 at sqrt(2) (slot 1, the maximum).
    std::vector<SampledQuery> v{record(0, s.q[0], 0, 1.0f, 0, RTHDIST_DEAD),
                                record(1, s.q[1], 1, 2.0f, 0, RTHDIST_EXACT)};
    v.push_back(v.back());
    EXPECT_EQ(sampledQueryFailure(v, s.q, s.t, packed(2.0f, 1), false), "");
}

TEST(SampledQueries, CatchWhatAWrappedOffsetProduces) {
    TwoSets s;
    const uint64_t max = packed(2.0f, 1);
    // The record holds another point than the one its index names.
    std::vector<SampledQuery> v{record(1, s.q[0], 1, 2.0f, 0, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
    // A stored distance that is not the named pair's.
    v = {record(1, s.q[1], 1, 1.5f, 0, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
    // An index past the set.
    v = {record(1, s.q[1], 7, 2.0f, 0, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
    v = {record(1, s.q[1], 1, 2.0f, 9, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
    // A query never settled, or settled above the maximum.
    v = {record(1, s.q[1], 1, 2.0f, 0, RTHDIST_OPEN)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
    v = {record(1, s.q[1], 1, 2.0f, 0, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, packed(1.0f, 1), false), "");
    // Per-point runs leave no query dead.
    v = {record(0, s.q[0], 0, 1.0f, 0, RTHDIST_DEAD)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, true), "");
    // A witness that is not the maximum's slot (the A[0] -> B[0]).
    v = {record(0, s.q[0], 0, 1.0f, 0, RTHDIST_EXACT)};
    EXPECT_NE(sampledQueryFailure(v, s.q, s.t, max, false), "");
}

TEST(Witness, AgreesWithTheDeviceMaximumOrFails) {
    EXPECT_EQ(witnessFailure(std::sqrt(2.0), packed(2.0f, 0), 1.0), "");
    EXPECT_NE(witnessFailure(2.0878, packed(1e-6f, 0), 0.0), "") << "the issue's H = 2.0878";
    EXPECT_NE(witnessFailure(1.0, packed(1.0f, 0), 2.0), "") << "below the lower bound";
    EXPECT_EQ(witnessFailure(0.0, packed(0.0f, 5), 0.0), "");
}

TEST(DeviceLimits, RefuseWithTheLimitNamed) {
    EXPECT_NO_THROW(gpu::requireWithin(uint64_t(1) << 32, uint64_t(1) << 32, "a buffer", "maxBufferSize"));
    try {
        gpu::requireWithin((uint64_t(1) << 32) + 16, uint64_t(1) << 32, "a buffer", "maxBufferSize");
        ADD_FAILURE() << "no throw";
    } catch (const gpu::LimitError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("maxBufferSize"), std::string::npos) << what;
        EXPECT_NE(what.find("4294967312"), std::string::npos) << what;
        EXPECT_NE(what.find("4294967296"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace rthdist::gpu_algo
