// Locale-free number parsing (std::from_chars) and float narrowing.
#pragma once

#include <glm/vec3.hpp>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>
#include <system_error>

namespace rthdist::io {

namespace detail {
template <class Real>
bool parseReal(std::string_view token, Real& out) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return false;
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, out);
    if (ec == std::errc::result_out_of_range && ptr == end) {
        // Overflow becomes an infinity (reported as a non-finite coordinate);
        // underflow becomes zero, as strtof/strtod would give.
        const size_t e = token.find_first_of("eE");
        const bool tiny = e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
        const Real inf = std::numeric_limits<Real>::infinity();
        out = tiny ? Real(0) : (token.front() == '-' ? -inf : inf);
        if (tiny && token.front() == '-') out = -Real(0);
        return true;
    }
    return ec == std::errc() && ptr == end;
}
}  // namespace detail

// Parses the WHOLE token as a decimal number straight to float (or double):
// one correctly rounded conversion (float through double could round twice).
// "+1.5e3", "nan" and "inf" are accepted; the finiteness check is the caller's.
[[nodiscard]] inline bool parseFloat(std::string_view token, float& out) {
    return detail::parseReal(token, out);
}
[[nodiscard]] inline bool parseDouble(std::string_view token, double& out) {
    return detail::parseReal(token, out);
}

// Parses the whole token as a non-negative decimal integer.
[[nodiscard]] inline bool parseUInt(std::string_view token, uint64_t& out) {
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return false;
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, out);
    return ec == std::errc() && ptr == end;
}

// double -> float without undefined behaviour: magnitudes beyond FLT_MAX
// become infinities (and are then rejected as non-finite coordinates).
[[nodiscard]] inline float narrowToFloat(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
    if (v > kMax) return std::numeric_limits<float>::infinity();
    if (v < -kMax) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(v);
}

// Parses tok[0], tok[1], tok[2] as x, y, z (the text loaders' shared step).
// Returns the first token that is not a number, for the caller's error.
[[nodiscard]] inline std::optional<std::string_view> parsePoint(const std::string_view* tok,
                                                                glm::dvec3& out) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!parseDouble(tok[axis], out[axis])) return tok[axis];
    }
    return std::nullopt;
}

}  // namespace rthdist::io
