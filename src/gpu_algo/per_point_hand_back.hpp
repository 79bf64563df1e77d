// CallOptions::perPointReady on the GPU backends: a direction's per-point
// nearest points handed to the caller's callback as soon as they are final.
// All but the last direction of a call go to a thread of the hand-back's own
// (their read-back from the device's copy included), so that the caller's
// work on them overlaps the device's search of the next direction; the last
// goes on the calling thread once that thread has returned. The callback's
// calls never overlap.
//
// Contract: every thread is joined before the hand-back is destroyed (also
// when the call throws); what a thread threw is rethrown by the next
// handHere() or join(). `handed` gains bit k when direction k is handed
// (GpuHausdorff::handedBack). The arrays handed must outlive the hand-back.
// Threading: one calling thread.
#pragma once

#include <cstdint>
#include <exception>
#include <thread>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/query_check.hpp"
#include "rthdist/options.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu_algo {

class PerPointHandBack {
public:
    PerPointHandBack(const CallOptions& options, QueryCheck& check, uint32_t& handed)
        : m_options(options), m_check(check), m_handed(handed) {}
    ~PerPointHandBack() = default;  // the std::jthread joins
    PerPointHandBack(const PerPointHandBack&) = delete;
    PerPointHandBack& operator=(const PerPointHandBack&) = delete;

    // Reads d's per-point output into `out` and calls the callback for
    // `direction`, on a thread of its own (the previous one joined first).
    void handBeside(const DirectionRun& d, PerPoint& out, int direction);
    // Calls the callback for `direction` with `out` (already read) on this
    // thread, after the thread's own call.
    void handHere(const PerPoint& out, int direction);
    // Waits for the thread; rethrows what it threw.
    void join();

private:
    const CallOptions& m_options;
    QueryCheck& m_check;
    uint32_t& m_handed;
    std::exception_ptr m_failed;  // declared before the thread: outlives it
    std::jthread m_thread;
};

}  // namespace rthdist::gpu_algo
