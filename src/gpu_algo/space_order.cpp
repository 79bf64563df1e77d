#include "gpu_algo/space_order.hpp"

#include <algorithm>
#include <cstdint>

namespace rthdist::gpu_algo {

bool inSpaceOrder(std::span<const glm::vec3> pts, const core::GridSpec& grid, size_t minPoints) {
    constexpr size_t kRuns = 64, kRun = 32;
    if (pts.size() < std::max(minPoints, kRuns * kRun)) return false;
    const uint32_t keyBits = 3 * uint32_t(grid.bits);
    const uint64_t narrow = keyBits > 8 ? uint64_t(1) << (keyBits - 8) : 1;
    const auto keyOf = [&](const glm::vec3& p) {
        uint32_t c[3];
        for (int axis = 0; axis < 3; ++axis)
            c[axis] = core::cellCoord(double(p[axis]), grid.origin[axis], grid.cellSize, grid.cellsPerAxis);
        return core::mortonEncode(c[0], c[1], c[2]);
    };
    size_t ordered = 0;
    for (size_t r = 0; r < kRuns; ++r) {
        const size_t first = r * (pts.size() - kRun) / (kRuns - 1);
        uint32_t lo = UINT32_MAX, hi = 0;
        for (size_t i = first; i < first + kRun; ++i) {
            const uint32_t key = keyOf(pts[i]);
            lo = std::min(lo, key);
            hi = std::max(hi, key);
        }
        if (uint64_t(hi - lo) < narrow) ++ordered;
    }
    return ordered > kRuns / 2;
}

}  // namespace rthdist::gpu_algo
