#include "cli/progress_meter.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace rthdist::cli {

ProgressMeter::ProgressMeter(bool enabled, std::chrono::milliseconds delay)
    : m_enabled(enabled), m_start(Clock::now()), m_delay(delay) {
    if (const char* env = std::getenv("RTHDIST_PROGRESS_DELAY_MS")) {
        m_delay = std::chrono::milliseconds(std::strtol(env, nullptr, 10));
    }
}

ProgressMeter::~ProgressMeter() { finish(); }

bool ProgressMeter::stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

void ProgressMeter::update(const char* stage, double fraction) {
    if (!m_enabled) return;
    const Clock::time_point now = Clock::now();
    if (now - m_start < m_delay) return;
    if (m_shown && now - m_lastPrint < std::chrono::milliseconds(100) && fraction < 1.0) return;
    m_lastPrint = now;
    char line[128];
    const int n = std::snprintf(line, sizeof line, "rthdist: %-8s %3d%%", stage,
                                int(std::clamp(fraction, 0.0, 1.0) * 100.0));
    std::string text = "\r";  // then the line appended (GCC 12's -Wrestrict misreads "\r" + std::string&&)
    text.append(line, size_t(std::max(n, 0)));
    const size_t visible = text.size() - 1;
    if (visible < m_width) text.append(m_width - visible, ' ');
    m_width = std::max(m_width, visible);
    std::fputs(text.c_str(), stderr);
    std::fflush(stderr);
    m_shown = true;
}

void ProgressMeter::finish() {
    if (!m_shown) return;
    std::fprintf(stderr, "\r%*s\r", int(m_width), "");
    std::fflush(stderr);
    m_shown = false;
}

}  // namespace rthdist::cli
