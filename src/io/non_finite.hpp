// Whether a run of points holds a NaN or an infinity, as one OR over the
// exponent bits with no early exit, so that the loop vectorizes: the
// loaders check whole chunks this way and look for the first bad point only
// in a chunk that has one.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

namespace rthdist::io {

template <class Vec>
[[nodiscard]] bool anyNonFinite(const Vec* p, size_t n) {
    using Real = typename Vec::value_type;
    using Bits = std::conditional_t<sizeof(Real) == 8, uint64_t, uint32_t>;
    constexpr Bits kExponent = std::bit_cast<Bits>(std::numeric_limits<Real>::infinity());
    Bits bad = 0;
    for (size_t i = 0; i < n; ++i) {
        bad |= static_cast<Bits>((std::bit_cast<Bits>(p[i].x) & kExponent) == kExponent) |
               static_cast<Bits>((std::bit_cast<Bits>(p[i].y) & kExponent) == kExponent) |
               static_cast<Bits>((std::bit_cast<Bits>(p[i].z) & kExponent) == kExponent);
    }
    return bad != 0;
}

}  // namespace rthdist::io
