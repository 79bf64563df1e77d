// The library's one read of the environment (src/core/tuning.cpp): every
// variable of README "Tuning" lands in its field; unset or unparsable values
// leave the library's choice.
#include <gtest/gtest.h>

#include "common/scoped_env.hpp"
#include "rthdist/tuning.hpp"

namespace rthdist::test {
namespace {

TEST(Tuning, EveryVariableLandsInItsField) {
    const ScopedEnv a("RTHDIST_SMALL_PAIR_WORK", "0"), b("RTHDIST_SEARCH_RADII", "3"),
        c("RTHDIST_SEARCH_TAIL", "0"), d("RTHDIST_TAIL_SCAN_WORK", "12345"),
        e("RTHDIST_TAIL_SCAN_START", "4294967296"), f("RTHDIST_HOST_IMPORT", "1"),
        g("RTHDIST_DEBUG_LABELS", "yes"), h("RTHDIST_SUBMIT_TRACE", "1"), i("RTHDIST_FENCE_SPIN_US", "7"),
        j("RTHDIST_POOL_SPIN_US", "0"), k("RTHDIST_CACHE_DIR", "/tmp/rthdist-tuning-test"),
        l("RTHDIST_SWEEP_WORK", "99"), m("RTHDIST_NARROW_HOST_BOUNDS", "0"),
        n("RTHDIST_NARROWED_INGEST", "1");
    const Tuning t = tuningFromEnvironment();
    EXPECT_EQ(t.smallPairWork, 0u);
    EXPECT_EQ(t.searchRadiiPerSubmission, 3u);
    EXPECT_EQ(t.squaredTailGrowth, false);
    EXPECT_EQ(t.tailScanWork, 12345u);
    EXPECT_EQ(t.tailScanStartWork, uint64_t(1) << 32);
    EXPECT_EQ(t.sweepWork, 99u);
    EXPECT_TRUE(t.hostImport);
    EXPECT_EQ(t.narrowHostBounds, false);
    EXPECT_EQ(t.narrowedIngest, true);
    EXPECT_TRUE(t.debugLabels);
    EXPECT_TRUE(t.traceSubmits);
    EXPECT_EQ(t.fenceSpinMicros, 7u);
    EXPECT_EQ(t.poolSpinMicros, 0u);
    EXPECT_EQ(t.pipelineCacheDir, "/tmp/rthdist-tuning-test");
}

TEST(Tuning, UnsetOrUnparsableLeavesTheLibrarysChoice) {
    const ScopedEnv a("RTHDIST_SMALL_PAIR_WORK", nullptr), b("RTHDIST_SEARCH_RADII", "three"),
        c("RTHDIST_SEARCH_TAIL", nullptr), d("RTHDIST_TAIL_SCAN_WORK", "-5"),
        e("RTHDIST_TAIL_SCAN_START", ""), f("RTHDIST_HOST_IMPORT", "yes"), g("RTHDIST_DEBUG_LABELS", "0"),
        h("RTHDIST_SUBMIT_TRACE", nullptr), i("RTHDIST_FENCE_SPIN_US", "12us"),
        j("RTHDIST_POOL_SPIN_US", nullptr), k("RTHDIST_CACHE_DIR", nullptr), l("XDG_CACHE_HOME", "/tmp/xdg"),
        m("HOME", "/tmp/home"), n("RTHDIST_SWEEP_WORK", "x"), o("RTHDIST_NARROW_HOST_BOUNDS", nullptr),
        q("RTHDIST_NARROWED_INGEST", nullptr);
    const Tuning t = tuningFromEnvironment();
    EXPECT_FALSE(t.smallPairWork);
    EXPECT_FALSE(t.searchRadiiPerSubmission);
    EXPECT_FALSE(t.squaredTailGrowth);
    EXPECT_FALSE(t.tailScanWork);
    EXPECT_FALSE(t.tailScanStartWork);
    EXPECT_FALSE(t.sweepWork);
    EXPECT_FALSE(t.hostImport);
    EXPECT_FALSE(t.narrowHostBounds);
    EXPECT_FALSE(t.narrowedIngest);
    EXPECT_FALSE(t.debugLabels);
    EXPECT_FALSE(t.traceSubmits);
    EXPECT_FALSE(t.fenceSpinMicros);
    EXPECT_FALSE(t.poolSpinMicros);
    EXPECT_EQ(t.pipelineCacheDir, "/tmp/xdg/rthdist");
    const ScopedEnv noXdg("XDG_CACHE_HOME", nullptr);
    EXPECT_EQ(tuningFromEnvironment().pipelineCacheDir, "/tmp/home/.cache/rthdist");
}

}  // namespace
}  // namespace rthdist::test
