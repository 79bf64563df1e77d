// The one clock of the stage timings (Timings, MaskResult, the tools'
// reports): the steady clock, read as milliseconds since a start. Header
// only, no dependency: the layers of src/ and the tools include it alike.
#pragma once

#include <chrono>

namespace rthdist::core {

using Clock = std::chrono::steady_clock;

// Milliseconds from `start` to now, in double (sub-microsecond resolution).
[[nodiscard]] inline double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace rthdist::core
