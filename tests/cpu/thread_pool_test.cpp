// core::parallelChunks over the process-wide worker pool (core/parallel.hpp,
// core/thread_pool.hpp): every index once, thread indices owned by one
// thread and below the resolved count, nested calls and many application
// threads at once completing, the pool reusing its threads and growing only
// to what calls ask for, and a forked child running its calls alone. Threads
// are told apart by their kernel ids (gettid), which fresh threads do not
// reuse the way std::thread::id values are. No timings.
#include <gtest/gtest.h>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>
#include <vector>

#include "core/parallel.hpp"
#include "core/sanitizers.hpp"
#include "core/thread_pool.hpp"

namespace rthdist::core {
namespace {

int hardwareThreads() { return std::max(1, int(std::thread::hardware_concurrency())); }

// The kernel ids of the threads that ran chunks, and which thread each
// thread index belonged to within one call.
class ThreadLog {
public:
    explicit ThreadLog(int threads) : m_owner(size_t(threads)) {}
    // False when threadIndex is out of range or was used by another thread.
    bool record(int threadIndex) {
        const pid_t self = gettid();
        {
            std::lock_guard lock(m_mutex);
            m_threads.insert(self);
            m_indices.insert(threadIndex);
        }
        if (threadIndex < 0 || size_t(threadIndex) >= m_owner.size()) return false;
        pid_t expected = 0;
        return m_owner[size_t(threadIndex)].compare_exchange_strong(expected, self) || expected == self;
    }
    size_t threads() const { return m_threads.size(); }
    size_t indices() const { return m_indices.size(); }
    pid_t owner(int threadIndex) const { return m_owner[size_t(threadIndex)].load(); }

private:
    std::vector<std::atomic<pid_t>> m_owner;
    std::mutex m_mutex;
    std::set<pid_t> m_threads;
    std::set<int> m_indices;
};

// Some work per element, so that helpers have time to join.
uint64_t mix(uint64_t x) {
    for (int k = 0; k < 64; ++k) x = x * 6364136223846793005ull + 1442695040888963407ull;
    return x;
}

// Runs one call over [0, count) and checks the chunks it was given; false on
// a chunk out of place or an index not covered exactly once.
bool coversEveryIndexOnce(size_t count, size_t chunk, int threads) {
    std::vector<std::atomic<uint8_t>> hits(count);
    std::atomic<bool> badChunk{false};
    const size_t step = std::max<size_t>(chunk, 1);  // a chunk of 0 means 1
    parallelChunks(count, chunk, threads, [&](size_t begin, size_t end, int) {
        if (begin % step != 0 || end != std::min(count, begin + step) || begin >= end) badChunk = true;
        for (size_t i = begin; i < end; ++i) hits[i].fetch_add(1, std::memory_order_relaxed);
    });
    return !badChunk && std::all_of(hits.begin(), hits.end(), [](const auto& h) { return h.load() == 1; });
}

TEST(ParallelChunks, EveryIndexExactlyOnce) {
    for (size_t count : {size_t(0), size_t(1), size_t(7), size_t(1000), size_t(50021)}) {
        for (size_t chunk : {size_t(0), size_t(1), size_t(3), size_t(64), size_t(100000)}) {
            for (int threads : {0, 1, 2, 3, 8}) {
                SCOPED_TRACE(testing::Message()
                             << "count " << count << " chunk " << chunk << " threads " << threads);
                EXPECT_TRUE(coversEveryIndexOnce(count, chunk, threads));
            }
        }
    }
}

TEST(ParallelChunks, ThreadIndexOwnedByOneThreadAndBelowTheCount) {
    for (int threads : {2, 3, 4, 8}) {
        SCOPED_TRACE(testing::Message() << "threads " << threads);
        ThreadLog log(threads);
        std::vector<std::atomic<bool>> inUse(static_cast<size_t>(threads));
        std::atomic<bool> bad{false};
        std::atomic<uint64_t> sink{0};
        parallelChunks(512, 1, threads, [&](size_t begin, size_t, int w) {
            if (!log.record(w)) {
                bad = true;
                return;
            }
            // Two workers with the same index at once would find it taken.
            if (inUse[size_t(w)].exchange(true)) bad = true;
            sink += mix(begin);
            inUse[size_t(w)] = false;
        });
        EXPECT_FALSE(bad);
        // The caller is worker 0 (when it got a chunk: helpers may take them all).
        EXPECT_TRUE(log.owner(0) == 0 || log.owner(0) == gettid());
        EXPECT_LE(log.indices(), size_t(threads));
        EXPECT_LE(log.threads(), size_t(threads));
    }
}

TEST(ParallelChunks, OneThreadRunsInlineOnTheCaller) {
    const size_t workers = poolWorkerCount();
    for (auto [count, chunk, threads] :
         {std::tuple{size_t(100), size_t(7), 1}, std::tuple{size_t(5), size_t(10), 8}}) {
        ThreadLog log(1);
        bool bad = false;  // written by this thread only: the call runs inline
        parallelChunks(count, chunk, threads, [&](size_t, size_t, int w) { bad |= !log.record(w); });
        EXPECT_FALSE(bad);
        EXPECT_EQ(log.threads(), 1u);
        EXPECT_EQ(log.owner(0), gettid());
    }
    EXPECT_EQ(poolWorkerCount(), workers);
}

// balancedChunk: ~four chunks a thread between its bounds, so a small pass
// still spreads over the threads and a large one keeps large chunks.
TEST(BalancedChunk, FourChunksAThreadWithinTheBounds) {
    EXPECT_EQ(balancedChunk(36000, 16, 256, 4096), 36000u / 64 + 1);  // 64 chunks for 16 threads
    EXPECT_EQ(balancedChunk(36000, 16), size_t(1) << 11);             // the default floor
    EXPECT_EQ(balancedChunk(100, 16, 256, 4096), 256u);               // never below the floor
    EXPECT_EQ(balancedChunk(size_t(1) << 30, 16), size_t(1) << 16);   // nor past the ceiling
    EXPECT_EQ(balancedChunk(1000, 2, 8, 1 << 20), 1000u / 8 + 1);
    // A ceiling below the floor gives the floor.
    EXPECT_EQ(balancedChunk(size_t(1) << 30, 4, 512, 64), 512u);
}

// Three levels of calls, each fn starting the next: each level counts its
// elements, and every call must complete however busy the pool is.
TEST(ParallelChunks, NestedCallsComplete) {
    std::atomic<uint64_t> leaves{0};
    std::atomic<bool> bad{false};
    parallelChunks(8, 1, 4, [&](size_t, size_t, int) {
        parallelChunks(16, 2, 4, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) {
                if (!coversEveryIndexOnce(300, 7, 3)) bad = true;
                leaves += 300;
            }
        });
    });
    EXPECT_FALSE(bad);
    EXPECT_EQ(leaves.load(), 8u * 16u * 300u);
}

TEST(ParallelChunks, ManyApplicationThreadsAtOnce) {
    constexpr int kCallers = 8;
    constexpr int kCallsEach = 25;
    std::atomic<int> failures{0};
    std::vector<std::thread> callers;
    for (int c = 0; c < kCallers; ++c) {
        callers.emplace_back([&, c] {
            for (int k = 0; k < kCallsEach; ++k) {
                const int threads = 2 + (c + k) % 4;
                if (!coversEveryIndexOnce(2000 + size_t(k), 16, threads)) ++failures;
                // And one with nested calls inside.
                std::atomic<size_t> inner{0};
                parallelChunks(4, 1, threads, [&](size_t, size_t, int) {
                    if (coversEveryIndexOnce(100, 3, threads)) ++inner;
                });
                if (inner != 4) ++failures;
            }
        });
    }
    for (std::thread& t : callers) t.join();
    EXPECT_EQ(failures.load(), 0);
}

// Fresh threads per call would show about 200 * (threads - 1) kernel ids;
// the pool shows at most its workers and the caller.
TEST(ThreadPool, ReusesItsThreadsAcrossCalls) {
    const int threads = std::max(2, hardwareThreads());
    const size_t before = poolWorkerCount();
    std::mutex mutex;
    std::set<pid_t> seen;
    std::atomic<uint64_t> sink{0};
    for (int call = 0; call < 200; ++call) {
        parallelChunks(64, 1, threads, [&](size_t begin, size_t, int) {
            sink += mix(begin);
            std::lock_guard lock(mutex);
            seen.insert(gettid());
        });
    }
    const size_t limit = std::max(before, size_t(threads - 1));
    EXPECT_LE(poolWorkerCount(), limit);
    EXPECT_LE(seen.size(), limit + 1);
}

TEST(ThreadPool, GrowsOnlyToWhatACallAsksFor) {
    std::atomic<uint64_t> sink{0};
    for (int threads : {2, 3, 5}) {
        const size_t before = poolWorkerCount();
        parallelChunks(256, 1, threads, [&](size_t begin, size_t, int) { sink += mix(begin); });
        EXPECT_LE(poolWorkerCount(), std::max(before, size_t(threads - 1))) << "threads " << threads;
    }
}

// The child of a fork has none of the parent's workers and starts none: its
// calls complete on the calling thread alone (every index once, one thread
// id), and its exit does not wait for the parent's workers (std::exit runs
// the static destructors that join the pool).
TEST(ThreadPool, ForkedChildRunsCallsOnItsOwnThread) {
#ifdef RTHDIST_TSAN
    GTEST_SKIP() << "ThreadSanitizer does not support fork() of a multithreaded process";
#else
    ASSERT_TRUE(coversEveryIndexOnce(10000, 16, 4));
    ASSERT_GT(poolWorkerCount(), 0u);
    // Workers still starting up hold allocator locks under AddressSanitizer
    // (no fork handlers in GCC 12's): fork once every worker waits for work.
    while (poolIdleWorkerCount() < poolWorkerCount()) std::this_thread::yield();
    std::fflush(nullptr);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        alarm(120);  // a hang guard, not a timing: a hung child fails the test
        ThreadLog log(4);
        std::atomic<bool> bad{false};
        parallelChunks(512, 1, 4, [&](size_t, size_t, int w) {
            if (!log.record(w)) bad = true;
        });
        const bool oneThread = log.threads() == 1 && log.owner(0) == gettid();
        const bool ok = !bad && oneThread && poolWorkerCount() == 0 && coversEveryIndexOnce(10000, 16, 4) &&
                        coversEveryIndexOnce(10000, 1, 3);
        std::exit(ok ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status)) << "child status " << status;
    EXPECT_EQ(WEXITSTATUS(status), 0);
    // The parent's pool still serves the parent.
    EXPECT_TRUE(coversEveryIndexOnce(10000, 16, 4));
#endif
}

}  // namespace
}  // namespace rthdist::core
