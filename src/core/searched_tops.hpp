// The largest of a device search's squared distances by chunks of a pass
// (the surface proof's q* and the chunks its band passes over,
// api/surface_certify.cpp), summarized where the distances are written (the
// GPU surface search's read-back, gpu_algo/surface_search.cpp) so that the
// proof does not pass over them again.
//
// Contract: the order is searchedKey's, a distance that is not a number >= 0
// (none found: +inf; NaN; negative) above every other, then the larger; on
// a tie the smaller index. Every function is pure; threading: any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace rthdist::core {

[[nodiscard]] inline float searchedKey(float d2) {
    return d2 >= 0.0f ? d2 : std::numeric_limits<float>::infinity();
}

struct SearchedTops {
    size_t chunk = 0;           // queries a chunk; 0: nothing summarized
    std::vector<uint64_t> top;  // per chunk [c * chunk, (c + 1) * chunk): its first query of the largest key

    // A chunk's first query of the largest key, its queries [begin, end)
    // read in index order (strict >: the first of a tie stays).
    [[nodiscard]] static uint64_t topOf(std::span<const float> d2, size_t begin, size_t end) {
        uint64_t top = begin;
        float largest = searchedKey(d2[begin]);  // (in a register: no reload of d2[top])
        for (size_t q = begin + 1; q < end; ++q) {
            const float key = searchedKey(d2[q]);
            if (key > largest) {
                largest = key;
                top = q;
            }
        }
        return top;
    }
    // The first query of the largest key of all (the chunks in order).
    [[nodiscard]] uint64_t overall(std::span<const float> d2) const {
        uint64_t best = top.front();
        for (const uint64_t t : top)
            if (searchedKey(d2[t]) > searchedKey(d2[best])) best = t;
        return best;
    }
    // Whether it summarizes n distances.
    [[nodiscard]] bool covers(size_t n) const {
        return chunk > 0 && n > 0 && top.size() == (n + chunk - 1) / chunk;
    }
};

}  // namespace rthdist::core
