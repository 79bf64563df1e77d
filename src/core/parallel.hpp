// Fork-join over fixed-size chunks for the host work of both backends:
// dynamic scheduling through one atomic counter, the helpers taken from the
// one process-wide pool (core/thread_pool.hpp) instead of fresh threads.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <thread>
#include <type_traits>

#include "core/thread_pool.hpp"

namespace rthdist::core {

// 0 -> all hardware threads; never more threads than chunks of work.
[[nodiscard]] inline int resolveThreads(int requested, size_t work = ~size_t(0)) {
    int t = requested > 0 ? requested : int(std::thread::hardware_concurrency());
    t = std::max(t, 1);
    if (work < size_t(t)) t = int(std::max<size_t>(work, 1));
    return t;
}

// A chunk size for a pass over `count` light elements on `threads` threads
// (0: all): about four chunks a thread, at least `minimum` elements a chunk
// (a chunk's scheduling costs ~1 us) and at most `maximum`. A fixed large
// chunk leaves a small call's pass (36k points in 1<<16 chunks) on one
// thread of sixteen.
[[nodiscard]] inline size_t balancedChunk(size_t count, int threads, size_t minimum = size_t(1) << 11,
                                          size_t maximum = size_t(1) << 16) {
    const size_t wanted = count / (4 * size_t(resolveThreads(threads))) + 1;
    return std::clamp(wanted, minimum, std::max(minimum, maximum));
}

// The same for elements of a microsecond or more each (a BVH descent, a
// patch's bounds): 16 to 256 a chunk, so that a few hundred still spread
// over the threads (a fixed 256 left the surface-to-surface rounds and 453
// queries of a coarse mesh on one or two threads of sixteen).
[[nodiscard]] inline size_t heavyItemChunk(size_t count, int threads) {
    return balancedChunk(count, threads, 16, 256);
}

// Calls fn(chunkBegin, chunkEnd, threadIndex) once for each chunk of [0, count)
// of `chunk` elements (the last one shorter), pulled dynamically by up to
// resolveThreads(threads, chunks) workers: the caller is worker 0, the others
// are pool threads. threadIndex is used by one thread only within a call and
// is below the resolved thread count, so it can index per-thread arrays.
// Returns when every chunk has run; fn's writes are then visible to the caller.
// Threading: any thread, also from inside another call's fn (nested) and from
// many threads at once; it completes even when every pool thread is busy (the
// caller then runs the chunks itself). One resolved thread runs inline, with
// no pool involved. fn must not throw (with more than one worker a throw ends
// the process through std::terminate).
template <class Fn>
void parallelChunks(size_t count, size_t chunk, int threads, Fn&& fn) {
    if (count == 0) return;
    chunk = std::max<size_t>(chunk, 1);
    const size_t chunks = (count + chunk - 1) / chunk;
    threads = resolveThreads(threads, chunks);
    if (threads == 1) {
        for (size_t c = 0; c < chunks; ++c) fn(c * chunk, std::min(count, (c + 1) * chunk), 0);
        return;
    }
    using F = std::remove_reference_t<Fn>;
    static_assert(std::is_object_v<F>, "pass a callable object (a lambda), not a function");
    ChunkTask task;
    task.count = count;
    task.chunk = chunk;
    task.threads = threads;
    task.run = [](void* context, size_t begin, size_t end, int threadIndex) {
        (*static_cast<F*>(context))(begin, end, threadIndex);
    };
    task.context = const_cast<void*>(static_cast<const void*>(std::addressof(fn)));
    runOnPool(task);
}

// The per-task lists of a parallelChunks pass (one list per chunk, each in
// its chunk's order) joined in chunk order into one `Out` (a std::vector or
// UninitVector of their element type), allocated once.
template <class Out, class Parts>
[[nodiscard]] Out concatenateParts(const Parts& parts) {
    size_t total = 0;
    for (const auto& part : parts) total += part.size();
    Out all;
    all.reserve(total);
    for (const auto& part : parts) all.insert(all.end(), part.begin(), part.end());
    return all;
}

}  // namespace rthdist::core
