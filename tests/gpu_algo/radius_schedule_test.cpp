// The candidate search's radius schedule (src/gpu_algo/radius_schedule.hpp)
// on the host, no device: the first radius, the level of a radius, the radii
// of each submission and their chunk, the squared growth of a far tail, the
// retry after a pair overflow and the far tail's switch to a level scan.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "gpu_algo/radius_schedule.hpp"

namespace rthdist::gpu_algo {
namespace {

// A grid of unit cells and 10 bits (levels 1 .. 9), no leaves.
SearchGrid unitGrid() { return SearchGrid{1.0, 10, false, 0.0}; }

RadiiOutcome reported(uint32_t run, uint32_t stillOpen, bool overflowed = false) {
    RadiiOutcome out;
    out.run = run;
    out.stillOpen = stillOpen;
    out.overflowed = overflowed;
    return out;
}

TEST(RadiusSchedule, StartsAtTwoCells) {
    EXPECT_EQ(RadiusSchedule::startRadius(SearchGrid{0.5, 8, false, 0.0}), 1.0);
    // Leaves' edges count only on a split index.
    EXPECT_EQ(RadiusSchedule::startRadius(SearchGrid{0.5, 8, false, 0.1}), 1.0);
}

TEST(RadiusSchedule, SplitIndexStartsAtHalfTheNarrowestLeaf) {
    EXPECT_EQ(RadiusSchedule::startRadius(SearchGrid{1.0, 8, true, 0.25}), 0.125);
    EXPECT_EQ(RadiusSchedule::startRadius(SearchGrid{1.0, 8, true, 10.0}), 2.0);  // never past 2 cells
    EXPECT_EQ(RadiusSchedule::startRadius(SearchGrid{1.0, 8, true, 0.0}), 2.0);   // no leaf edge known
}

TEST(RadiusSchedule, LevelCellsAreAnEighthOfTheRadius) {
    const SearchGrid g = unitGrid();
    EXPECT_EQ(RadiusSchedule::levelFor(g, 0.01), 1);  // at least 1
    EXPECT_EQ(RadiusSchedule::levelFor(g, 16.0), 1);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 31.9), 1);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 32.0), 2);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 64.0), 3);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 1e12), 9);  // at most bits - 1
    EXPECT_EQ(RadiusSchedule::levelFor(SearchGrid{1.0, 1, false, 0.0}, 1e12), 1);
}

TEST(RadiusSchedule, SplitIndexSearchesItsLeavesUntilLevelOne) {
    const SearchGrid g{1.0, 10, true, 0.1};
    EXPECT_EQ(RadiusSchedule::levelFor(g, 0.05), 0);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 15.9), 0);
    EXPECT_EQ(RadiusSchedule::levelFor(g, 16.0), 1);
}

TEST(RadiusSchedule, TailGrowsBySquareWhenFewAreLeftAndMostGoOn) {
    // 800 searched: "few" is at most 100; "most" is more than half of the submission's.
    EXPECT_EQ(RadiusSchedule::tailStep(2.0, 800, 150, 100), 4.0);
    EXPECT_EQ(RadiusSchedule::tailStep(2.0, 800, 150, 101), 2.0);  // not few
    EXPECT_EQ(RadiusSchedule::tailStep(2.0, 800, 150, 75), 2.0);   // exactly half: not most
    EXPECT_EQ(RadiusSchedule::tailStep(2.0, 800, 150, 76), 4.0);
    EXPECT_EQ(RadiusSchedule::tailStep(1.5, 800, 0, 0), 1.5);  // nothing going on
}

// The submissions of a search that thins out slowly over a unit grid with
// growth 2: the chunk doubles while most queries go on, the radii of a
// submission stay at one level, and the next submission starts at the last
// radius times the step.
TEST(RadiusSchedule, SubmissionsStayAtOneLevelAndTheChunkDoubles) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    EXPECT_FALSE(s.traced());
    EXPECT_EQ(s.chunk(), 2u);
    EXPECT_EQ(s.level(), 1);
    std::vector<double> radii = s.nextRadii();
    EXPECT_EQ(radii, (std::vector<double>{2.0, 4.0}));

    s.advance(radii, 1000, reported(2, 900));
    EXPECT_TRUE(s.traced());
    EXPECT_EQ(s.chunk(), 4u);
    EXPECT_EQ(s.step(), 2.0);
    radii = s.nextRadii();
    EXPECT_EQ(radii, (std::vector<double>{8.0, 16.0}));  // 32 is level 2

    s.advance(radii, 900, reported(2, 500));
    EXPECT_EQ(s.chunk(), 8u);
    EXPECT_EQ(s.level(), 2);
    radii = s.nextRadii();
    EXPECT_EQ(radii, (std::vector<double>{32.0}));  // 64 is level 3

    s.advance(radii, 500, reported(1, 200));  // less than half went on
    EXPECT_EQ(s.chunk(), 2u);
    EXPECT_EQ(s.radius(), 64.0);
}

TEST(RadiusSchedule, ChunkStopsAtTheLogAndTheTuning) {
    ScheduleSettings settings;
    RadiusSchedule s(unitGrid(), settings, 1.001, 1000, 1000);
    for (int i = 0; i < 8; ++i) {
        const std::vector<double> radii = s.nextRadii();
        EXPECT_EQ(radii.size(), s.chunk());  // growth 1.001 stays at level 1
        s.advance(radii, 1000, reported(uint32_t(radii.size()), 1000));
    }
    EXPECT_EQ(s.chunk(), uint32_t(RTHDIST_SEARCH_LOG_MAX));
    EXPECT_EQ(s.nextRadii().size(), size_t(RTHDIST_SEARCH_LOG_MAX));

    settings.radiiPerSubmission = 3;
    RadiusSchedule few(unitGrid(), settings, 1.001, 1000, 1000);
    for (int i = 0; i < 4; ++i) {
        const std::vector<double> radii = few.nextRadii();
        EXPECT_LE(radii.size(), 3u);
        few.advance(radii, 1000, reported(uint32_t(radii.size()), 1000));
    }
    EXPECT_EQ(few.nextRadii().size(), 3u);
}

TEST(RadiusSchedule, OverflowRetriesTheLastRadiusThatSearched) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    const std::vector<double> radii = s.nextRadii();
    s.advance(radii, 1000, reported(1, 1000, true));
    EXPECT_EQ(s.radius(), 2.0);
    EXPECT_EQ(s.chunk(), 4u);
}

RadiiOutcome overflowedFull(uint32_t stillOpen, uint64_t pairs) {
    RadiiOutcome out = reported(1, stillOpen, true);
    out.lastPairs = pairs;
    return out;
}

// A buffer that can grow no more and overflows with most queries going on
// (on an H200 the retries met the same candidates every time): the queries
// take turns in classes by index at the same radius, one radius a
// submission, as many classes as the pairs fill the buffer twice over; the
// radius grows once every class had its turn.
TEST(RadiusSchedule, StalledFullBufferSearchesRetryClassesInTurn) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    EXPECT_EQ(s.retryClass().stride, 1u);
    s.advance(s.nextRadii(), 1000, overflowedFull(900, 250), 100);
    EXPECT_EQ(s.retryClass().stride, 5u);  // 2 x 250 pairs / 100
    EXPECT_EQ(s.retryClass().phase, 0u);
    EXPECT_EQ(s.radius(), 2.0);
    EXPECT_EQ(s.nextRadii(), (std::vector<double>{2.0}));
    for (uint32_t phase = 1; phase < 5; ++phase) {
        s.advance(s.nextRadii(), 900, reported(1, 850), 100);
        EXPECT_EQ(s.retryClass().stride, 5u);
        EXPECT_EQ(s.retryClass().phase, phase);
        EXPECT_EQ(s.radius(), 2.0);
    }
    s.advance(s.nextRadii(), 850, reported(1, 800), 100);  // the last class
    EXPECT_EQ(s.retryClass().stride, 1u);
    EXPECT_EQ(s.retryClass().phase, 0u);
    EXPECT_EQ(s.radius(), 4.0);
    EXPECT_FALSE(s.retryExhausted());
}

// A class that overflows the full buffer again is split (the stride a
// multiple of the old, its turns from the same phase on); an overflow while
// the buffer can still grow retries the same class; a class of at most one
// query that overflows is exhausted.
TEST(RadiusSchedule, RetryClassThatOverflowsIsSplitUntilOneQuery) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    s.advance(s.nextRadii(), 1000, overflowedFull(1000, 100), 100);
    EXPECT_EQ(s.retryClass().stride, 2u);
    s.advance(s.nextRadii(), 1000, reported(1, 990), 100);
    EXPECT_EQ(s.retryClass().phase, 1u);
    s.advance(s.nextRadii(), 990, overflowedFull(990, 300), 100);  // class 1 of 2 overflows
    EXPECT_EQ(s.retryClass().stride, 12u);                         // 2 x 6
    EXPECT_EQ(s.retryClass().phase, 1u);
    s.advance(s.nextRadii(), 990, overflowedFull(990, 300), 0);  // a buffer that grows: the same turn
    EXPECT_EQ(s.retryClass().stride, 12u);
    EXPECT_EQ(s.retryClass().phase, 1u);
    EXPECT_EQ(s.radius(), 2.0);
    while (s.retryClass().stride < 1000 && !s.retryExhausted())
        s.advance(s.nextRadii(), 990, overflowedFull(990, 1000), 100);
    EXPECT_FALSE(s.retryExhausted());
    s.advance(s.nextRadii(), 990, overflowedFull(990, 1000), 100);
    EXPECT_TRUE(s.retryExhausted());
}

// An overflow that still lets most queries finish, or one of a buffer that
// can grow, keeps every query in the search (no classes).
TEST(RadiusSchedule, NoRetryClassesWhileTheSearchProgresses) {
    RadiusSchedule grows(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    grows.advance(grows.nextRadii(), 1000, overflowedFull(1000, 500), 0);
    EXPECT_EQ(grows.retryClass().stride, 1u);
    RadiusSchedule progresses(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    progresses.advance(progresses.nextRadii(), 1000, overflowedFull(800, 500), 100);
    EXPECT_EQ(progresses.retryClass().stride, 1u);
    EXPECT_EQ(progresses.radius(), 2.0);
}

TEST(RadiusSchedule, RadiiThatSearchedNoQueryAreSkipped) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    // The first radius settled every query but one; the second had none.
    s.advance(s.nextRadii(), 1000, reported(1, 1));
    EXPECT_EQ(s.radius(), 2.0 * 2.0);
}

TEST(RadiusSchedule, FarTailGrowsBySquareUnlessTurnedOff) {
    // 1000 searched, 100 entered the submission, 90 go on: a far tail.
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 1000, 1000);
    s.advance(std::vector<double>{2.0, 4.0}, 100, reported(2, 90));
    EXPECT_EQ(s.step(), 4.0);
    EXPECT_EQ(s.radius(), 16.0);
    EXPECT_EQ(s.nextRadii(), (std::vector<double>{16.0}));  // 64 is level 3

    ScheduleSettings plain;
    plain.squaredTailGrowth = false;
    RadiusSchedule p(unitGrid(), plain, 2.0, 1000, 1000);
    p.advance(std::vector<double>{2.0, 4.0}, 100, reported(2, 90));
    EXPECT_EQ(p.step(), 2.0);
    EXPECT_EQ(p.radius(), 8.0);
}

// The cell counts of levels 1, 2, 3, ... and the levels asked for.
struct Levels {
    std::vector<uint32_t> cells;
    std::vector<int> asked;
    uint32_t operator()(int level) {
        asked.push_back(level);
        return cells.at(size_t(level - 1));
    }
};

ScheduleSettings tailSettings(uint64_t work, uint64_t startWork) {
    ScheduleSettings s;
    s.tailScanWork = work;
    s.tailScanStartWork = startWork;
    s.tailQueriesMax = 64;
    return s;
}

TEST(RadiusSchedule, TailScanBeforeAnyRadiusIsOffByDefault) {
    RadiusSchedule s(unitGrid(), ScheduleSettings{}, 2.0, 10, 100);
    Levels levels{{1, 1, 1}, {}};
    EXPECT_EQ(s.tailLevel(1, 0, std::ref(levels)), -1);
    EXPECT_TRUE(levels.asked.empty());  // no level built for nothing
}

TEST(RadiusSchedule, TailScanTakesTheFirstLevelOfFewCells) {
    // Before any radius: measured against the direction's 100 queries and the start work.
    RadiusSchedule s(unitGrid(), tailSettings(0, 1u << 20), 2.0, 50, 100);
    Levels levels{{10000, 5000, kTailScanCells, 10}, {}};
    EXPECT_EQ(s.tailLevel(25, 0, std::ref(levels)), 3);
    EXPECT_EQ(levels.asked, (std::vector<int>{1, 2, 3}));
    // Levels already built: the walk starts at the last of them.
    levels.asked.clear();
    EXPECT_EQ(s.tailLevel(25, 2, std::ref(levels)), 3);
    EXPECT_EQ(levels.asked, (std::vector<int>{2, 3}));
    // Too much work at that level: trace.
    RadiusSchedule tight(unitGrid(), tailSettings(0, 25 * kTailScanCells - 1), 2.0, 50, 100);
    EXPECT_EQ(tight.tailLevel(25, 0, std::ref(levels)), -1);
}

TEST(RadiusSchedule, TailScanNeedsFewOpenQueries) {
    RadiusSchedule s(unitGrid(), tailSettings(1u << 20, 1u << 20), 2.0, 50, 100);
    Levels levels{{10}, {}};
    EXPECT_EQ(s.tailLevel(26, 0, std::ref(levels)), -1);  // more than a quarter of 100
    // After radii: measured against the 50 searched and the work after radii.
    s.advance(s.nextRadii(), 50, reported(1, 20));
    EXPECT_EQ(s.tailLevel(13, 0, std::ref(levels)), -1);  // more than a quarter of 50
    EXPECT_EQ(s.tailLevel(12, 0, std::ref(levels)), 1);
    // At most a workgroup per query (tailQueriesMax).
    RadiusSchedule many(unitGrid(), tailSettings(1u << 20, 1u << 20), 2.0, 1000, 1000);
    EXPECT_EQ(many.tailLevel(65, 0, std::ref(levels)), -1);
    EXPECT_EQ(many.tailLevel(64, 0, std::ref(levels)), 1);
    EXPECT_EQ(levels.asked, (std::vector<int>{1, 1}));
}

TEST(RadiusSchedule, TailScanStopsAtTheGridsLastLevel) {
    // 4 bits: levels 1 .. 3; level 3 is scanned however many cells it has.
    RadiusSchedule s(SearchGrid{1.0, 4, false, 0.0}, tailSettings(0, uint64_t(1) << 40), 2.0, 10, 10);
    Levels levels{{90000, 80000, 70000, 1}, {}};
    EXPECT_EQ(s.tailLevel(1, 0, std::ref(levels)), 3);
    EXPECT_EQ(levels.asked, (std::vector<int>{1, 2, 3}));
}

TEST(RadiusSchedule, SweepWhileOpenTimesTargetsIsWithinTheLimit) {
    ScheduleSettings settings;
    settings.sweepWork = 1000;
    const RadiusSchedule s(unitGrid(), settings, 2.0, 10, 10);
    EXPECT_TRUE(s.sweeps(10, 100));
    EXPECT_FALSE(s.sweeps(11, 100));
    EXPECT_TRUE(s.sweeps(1, 1000));
    EXPECT_FALSE(s.sweeps(1, 1001));
    EXPECT_FALSE(s.sweeps(0xffffffffu, uint64_t(1) << 40));  // no overflow of open x targets
    settings.sweepWork = 0;                                  // never
    EXPECT_FALSE(RadiusSchedule(unitGrid(), settings, 2.0, 10, 10).sweeps(1, 1));
}

TEST(RadiusSchedule, SettingsFromTheTuning) {
    const ScheduleSettings gpu = scheduleSettings(Tuning{}, false, 1000);
    EXPECT_EQ(gpu.radiiPerSubmission, uint32_t(RTHDIST_SEARCH_LOG_MAX));
    EXPECT_TRUE(gpu.squaredTailGrowth);
    EXPECT_EQ(gpu.tailScanWork, kTailScanWorkGpu);
    EXPECT_EQ(gpu.tailScanStartWork, kTailScanStartWorkGpu);
    EXPECT_EQ(gpu.tailQueriesMax, 1000u);
    EXPECT_EQ(scheduleSettings(Tuning{}, true, 1000).tailScanWork, kTailScanWorkCpuDevice);
    EXPECT_EQ(gpu.sweepWork, kSweepWorkGpu);
    EXPECT_EQ(scheduleSettings(Tuning{}, true, 1000).sweepWork, kSweepWorkCpuDevice);

    Tuning t;
    t.searchRadiiPerSubmission = 0;
    t.squaredTailGrowth = false;
    t.tailScanWork = 7;
    t.tailScanStartWork = 9;
    t.sweepWork = 11;
    const ScheduleSettings tuned = scheduleSettings(t, true, 1000);
    EXPECT_EQ(tuned.radiiPerSubmission, 1u);  // clamped to 1 .. RTHDIST_SEARCH_LOG_MAX
    EXPECT_FALSE(tuned.squaredTailGrowth);
    EXPECT_EQ(tuned.tailScanWork, 7u);
    EXPECT_EQ(tuned.tailScanStartWork, 9u);
    EXPECT_EQ(tuned.sweepWork, 11u);
    t.searchRadiiPerSubmission = 1000;
    EXPECT_EQ(scheduleSettings(t, false, 1000).radiiPerSubmission, uint32_t(RTHDIST_SEARCH_LOG_MAX));
}

}  // namespace
}  // namespace rthdist::gpu_algo
