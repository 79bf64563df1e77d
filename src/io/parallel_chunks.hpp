// The loaders' fork-join helper: a file's records or lines are cut into
// chunks whose bounds depend only on ChunkPlan::chunkBytes (never on the
// thread count, so points and errors are the same with any number of
// threads), and the chunks are pulled in order from one atomic counter by
// std::threads. src/io does not depend on src/cpu; this is the loaders' own
// copy of the idea in src/cpu/parallel.hpp, plus exceptions carried back to
// the caller and a stop at the first failed chunk.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::io {

// Bytes of input per chunk when the plan does not say: a few hundred chunks
// per gigabyte, so two to a hundred threads stay busy to the end.
inline constexpr size_t kDefaultChunkBytes = size_t{2} << 20;

struct ChunkPlan {
    unsigned threads = 0;   // 0: every hardware thread
    size_t chunkBytes = 0;  // 0: kDefaultChunkBytes; tests force tiny chunks

    [[nodiscard]] size_t bytes() const { return chunkBytes == 0 ? kDefaultChunkBytes : chunkBytes; }
    // Items of itemBytes each per chunk (at least one).
    [[nodiscard]] uint64_t items(uint64_t itemBytes) const {
        return std::max<uint64_t>(1, bytes() / std::max<uint64_t>(itemBytes, 1));
    }
};

// Chunks of perChunk items that hold `items` items (no overflow near 2^64).
[[nodiscard]] inline size_t chunkCount(uint64_t items, uint64_t perChunk) {
    return items == 0 ? 0 : static_cast<size_t>((items - 1) / std::max<uint64_t>(perChunk, 1) + 1);
}

// Calls work(c) for every chunk c in [0, chunks), on up to plan.threads
// threads (the caller's included), and returns the error of the lowest
// chunk that failed: work returns std::nullopt or its chunk's first error.
// Chunks after a failed one are skipped (their errors come later in the
// file). An exception thrown by work (std::bad_alloc) is rethrown here once
// every thread has stopped.
template <class Work>
std::optional<Error> forEachChunk(size_t chunks, const ChunkPlan& plan, Work&& work) {
    if (chunks == 0) return std::nullopt;
    const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
    const size_t threads = std::min<size_t>(chunks, plan.threads == 0 ? hardware : plan.threads);
    std::vector<std::optional<Error>> errors(chunks);
    std::atomic<size_t> next{0};
    std::atomic<size_t> firstFailed{std::numeric_limits<size_t>::max()};
    std::exception_ptr thrown;
    std::mutex thrownMutex;
    auto worker = [&] {
        for (;;) {
            const size_t c = next.fetch_add(1, std::memory_order_relaxed);
            if (c >= chunks || c > firstFailed.load(std::memory_order_relaxed)) return;
            try {
                errors[c] = work(c);
            } catch (...) {
                const std::lock_guard<std::mutex> lock(thrownMutex);
                if (!thrown) thrown = std::current_exception();
                errors[c] = Error{};
            }
            if (!errors[c]) continue;
            size_t seen = firstFailed.load(std::memory_order_relaxed);
            while (c < seen && !firstFailed.compare_exchange_weak(seen, c, std::memory_order_relaxed)) {
            }
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(threads - 1);
    try {
        for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
    } catch (const std::system_error&) {
        // No more threads to be had: the ones started and the caller finish the work.
    }
    worker();
    for (std::thread& t : pool) t.join();
    if (thrown) std::rethrow_exception(thrown);
    for (std::optional<Error>& e : errors) {
        if (e) return std::move(e);
    }
    return std::nullopt;
}

}  // namespace rthdist::io
