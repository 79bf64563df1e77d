#include "gpu_algo/space_order.hpp"

#include <algorithm>
#include <cstdint>

namespace rthdist::gpu_algo {

bool inSpaceOrder(std::span<const glm::vec3> pts, const core::GridSpec& grid, size_t minPoints) {
    constexpr size_t kRuns = 64, kRun = 32;
    if (pts.size() < std::max(minPoints, kRuns * kRun)) return false;
    const uint32_t keyBits = 3 * uint32_t(grid.bits);
    const uint64_t narrow = keyBits > 8 ? uint64_t(1) << (keyBits - 8) : 1;
    size_t ordered = 0;
    for (size_t r = 0; r < kRuns; ++r) {
        const size_t first = r * (pts.size() - kRun) / (kRuns - 1);
        uint32_t lo = UINT32_MAX, hi = 0;
        for (size_t i = first; i < first + kRun; ++i) {
            const uint32_t key = core::cellKey(glm::dvec3(pts[i]), grid);
            lo = std::min(lo, key);
            hi = std::max(hi, key);
        }
        if (uint64_t(hi - lo) < narrow) ++ordered;
    }
    return ordered > kRuns / 2;
}

}  // namespace rthdist::gpu_algo
