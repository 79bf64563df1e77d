// Minimal fork-join helpers for the CPU backend: std::thread only, dynamic
// scheduling over fixed-size chunks through one atomic counter.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace rthdist::core {

// 0 -> all hardware threads; never more threads than chunks of work.
[[nodiscard]] inline int resolveThreads(int requested, size_t work = ~size_t(0)) {
    int t = requested > 0 ? requested : int(std::thread::hardware_concurrency());
    t = std::max(t, 1);
    if (work < size_t(t)) t = int(std::max<size_t>(work, 1));
    return t;
}

// Calls fn(chunkBegin, chunkEnd, threadIndex) for chunks of [0, count) of
// `chunk` elements, pulled dynamically by `threads` workers (the caller is
// worker 0). fn must not throw.
template <class Fn>
void parallelChunks(size_t count, size_t chunk, int threads, Fn&& fn) {
    if (count == 0) return;
    chunk = std::max<size_t>(chunk, 1);
    const size_t chunks = (count + chunk - 1) / chunk;
    threads = resolveThreads(threads, chunks);
    std::atomic<size_t> next{0};
    auto worker = [&](int t) {
        for (;;) {
            const size_t c = next.fetch_add(1, std::memory_order_relaxed);
            if (c >= chunks) break;
            const size_t begin = c * chunk;
            fn(begin, std::min(count, begin + chunk), t);
        }
    };
    if (threads == 1) {
        worker(0);
        return;
    }
    std::vector<std::thread> pool;
    pool.reserve(size_t(threads - 1));
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
    worker(0);
    for (std::thread& th : pool) th.join();
}

}  // namespace rthdist::core
