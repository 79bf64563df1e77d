// Point counts past 32 bits (issue 14) without 50 GB of points: the paths
// that decide sizes read counts only, so views of 2^32 + 5 points over a
// three-point buffer reach them. One-shot sets up to 2^40 points are
// accepted and split into pieces of at most 2^31 - 1 points per set (the
// backends' 32-bit indices); what cannot hold 64-bit indices (per-point
// output, prepared sets) is refused with its limit named, before any point
// is read.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "api/out_of_core.hpp"
#include "core/input_frame.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::test {
namespace {

constexpr uint64_t kPast32Bits = (uint64_t(1) << 32) + 5;

// A view of `count` points over a buffer of three: only counts may be read.
PointView countOnly(const glm::vec3* three, uint64_t count) {
    return PointView::floats(&three[0].x, size_t(count));
}

TEST(Counts64, ShapeAcceptsSetsPast32Bits) {
    const glm::vec3 three[3] = {};
    EXPECT_FALSE(core::checkShape(countOnly(three, kPast32Bits), "A"));
    EXPECT_FALSE(core::checkShape(countOnly(three, core::kMaxSetPoints), "A"));
    auto tooMany = core::checkShape(countOnly(three, core::kMaxSetPoints + 1), "A");
    ASSERT_TRUE(tooMany);
    EXPECT_NE(tooMany->message.find("2^40"), std::string::npos) << tooMany->message;
    // Past the address space: 2^40 points 2^30 bytes apart.
    auto wide = core::checkShape(PointView::floats(&three[0].x, size_t(1) << 40, size_t(1) << 30), "B");
    ASSERT_TRUE(wide);
    EXPECT_NE(wide->message.find("address space"), std::string::npos) << wide->message;
}

// No budget (the CPU backend's default) still splits at 2^31 - 1 points per
// set; every piece fits 32-bit indices and the pieces cover the set.
TEST(Counts64, SetsPast32BitsRunInPiecesOf31Bits) {
    const api::MemoryBudget unlimited;
    EXPECT_TRUE(api::fitsOneCall(unlimited, api::kMaxCallPoints, api::kMaxCallPoints));
    EXPECT_FALSE(api::fitsOneCall(unlimited, api::kMaxCallPoints + 1, 3));
    EXPECT_FALSE(api::fitsOneCall(unlimited, 3, kPast32Bits));
    for (uint64_t nq : {uint64_t(3), kPast32Bits, uint64_t(5'000'000'000)}) {
        for (uint64_t nt : {uint64_t(3), kPast32Bits, uint64_t(5'000'000'000)}) {
            for (int lanes : {1, 2, 8}) {
                auto split = api::splitDirection(unlimited, nq, nt, lanes);
                ASSERT_TRUE(split);
                EXPECT_LE(split->queryChunk, api::kMaxCallPoints);
                EXPECT_LE(split->targetTile, api::kMaxCallPoints);
                const uint64_t chunks = (nq + split->queryChunk - 1) / split->queryChunk;
                const uint64_t tiles = (nt + split->targetTile - 1) / split->targetTile;
                EXPECT_GE(chunks * split->queryChunk, nq);
                EXPECT_GE(chunks, std::min<uint64_t>(nq, uint64_t(lanes)));
                if (nt > api::kMaxCallPoints) EXPECT_GE(tiles, 3u);  // 2^32 + 5 > 2 (2^31 - 1)
            }
        }
    }
}

// Per-point output keeps 32-bit indices (PerPoint::nearest) and a prepared
// set is one call's set: both refused past their limits, naming them, before
// a point is read (the view's buffer holds three).
TEST(Counts64, WhatKeeps32BitIndicesIsRefusedBeforeReading) {
    const glm::vec3 three[3] = {};
    Options options;
    options.backend = Backend::kCpu;
    options.perPointDistances = true;
    auto perPoint = hausdorff(countOnly(three, 3), countOnly(three, kPast32Bits), options);
    ASSERT_FALSE(perPoint);
    EXPECT_EQ(perPoint.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(perPoint.error().message.find("2^32 - 1"), std::string::npos) << perPoint.error().message;

    EngineOptions cpu;
    cpu.backend = Backend::kCpu;
    auto engine = Engine::create(cpu);
    ASSERT_TRUE(engine);
    CallOptions call;
    call.perPointDistances = true;
    auto viaEngine = engine->compute(countOnly(three, kPast32Bits), countOnly(three, 3), call);
    ASSERT_FALSE(viaEngine);
    EXPECT_EQ(viaEngine.error().code, ErrorCode::kInvalidArgument);
    auto prepared = engine->prepare(countOnly(three, api::kMaxCallPoints + 1));
    ASSERT_FALSE(prepared);
    EXPECT_EQ(prepared.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(prepared.error().message.find("2^31 - 1"), std::string::npos) << prepared.error().message;
}

}  // namespace
}  // namespace rthdist::test
