// Progress on stderr for long runs: "rthdist: <stage> <percent>%" rewritten in
// place with '\r', only when stderr is a terminal, not before `delay` has
// passed since construction (short runs print nothing), and at most every
// 100 ms. finish() erases the line. Feeds from Options::progress, which the
// library calls from the calling thread, so no locking is needed.
// Test hook: the environment variable RTHDIST_PROGRESS_DELAY_MS overrides the
// delay (tests/cli runs a tiny input under `script` with it set to 0).
#pragma once

#include <chrono>
#include <string>

namespace rthdist::cli {

class ProgressMeter {
public:
    // enabled = false (--quiet, or stderr not a terminal): update() does nothing.
    explicit ProgressMeter(bool enabled, std::chrono::milliseconds delay = std::chrono::milliseconds(1000));
    ~ProgressMeter();
    ProgressMeter(const ProgressMeter&) = delete;
    ProgressMeter& operator=(const ProgressMeter&) = delete;

    // A stage of work outside the library (loading, writing outputs).
    void update(const char* stage, double fraction);
    void finish();

    // true when stderr is a terminal.
    [[nodiscard]] static bool stderrIsTerminal();

private:
    using Clock = std::chrono::steady_clock;
    bool m_enabled;
    bool m_shown = false;
    Clock::time_point m_start;
    Clock::time_point m_lastPrint;
    std::chrono::milliseconds m_delay;
    size_t m_width = 0;
};

}  // namespace rthdist::cli
