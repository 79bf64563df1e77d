// Per-point hand-back (per_point_hand_back.hpp).
#include "gpu_algo/per_point_hand_back.hpp"

#include <span>
#include <utility>

namespace rthdist::gpu_algo {

void PerPointHandBack::handBeside(const DirectionRun& d, PerPoint& out, int direction) {
    join();
    m_handed |= 1u << direction;
    m_thread = std::jthread([this, &d, &out, direction] {
        try {
            m_check.readPerPoint(d, out);  // reads only d's own read-back buffer
        } catch (...) {
            m_failed = std::current_exception();
            return;
        }
        m_options.perPointReady(direction, std::span<const uint32_t>(out.nearest));
    });
}

void PerPointHandBack::handHere(const PerPoint& out, int direction) {
    join();
    m_handed |= 1u << direction;
    m_options.perPointReady(direction, std::span<const uint32_t>(out.nearest));
}

void PerPointHandBack::join() {
    if (m_thread.joinable()) m_thread.join();
    if (m_failed) std::rethrow_exception(std::exchange(m_failed, nullptr));
}

}  // namespace rthdist::gpu_algo
