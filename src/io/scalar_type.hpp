// Fixed-size numeric types shared by the binary PLY, PCD and glTF readers,
// decoded from unaligned bytes in either byte order.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>

namespace rthdist::io {

enum class ScalarType {
    kInt8,
    kUInt8,
    kInt16,
    kUInt16,
    kInt32,
    kUInt32,
    kInt64,
    kUInt64,
    kFloat32,
    kFloat64
};

[[nodiscard]] constexpr size_t scalarSize(ScalarType t) {
    switch (t) {
        case ScalarType::kInt8:
        case ScalarType::kUInt8: return 1;
        case ScalarType::kInt16:
        case ScalarType::kUInt16: return 2;
        case ScalarType::kInt32:
        case ScalarType::kUInt32:
        case ScalarType::kFloat32: return 4;
        case ScalarType::kInt64:
        case ScalarType::kUInt64:
        case ScalarType::kFloat64: return 8;
    }
    return 1;
}

[[nodiscard]] constexpr bool isIntegral(ScalarType t) {
    return t != ScalarType::kFloat32 && t != ScalarType::kFloat64;
}

// True for the types a float cannot hold exactly (double, 32/64-bit
// integers): a binary x/y/z of one of these makes the loader keep doubles.
[[nodiscard]] constexpr bool needsDouble(ScalarType t) {
    return t == ScalarType::kFloat64 || t == ScalarType::kInt32 || t == ScalarType::kUInt32 ||
           t == ScalarType::kInt64 || t == ScalarType::kUInt64;
}

// PLY type names: char uchar short ushort int uint float double and the
// int8 uint8 int16 uint16 int32 uint32 float32 float64 aliases.
[[nodiscard]] std::optional<ScalarType> plyScalarType(std::string_view name);

namespace detail {
template <class T>
T loadRaw(const char* p, bool bigEndian) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (bigEndian != (std::endian::native == std::endian::big)) {
        for (size_t i = 0; i < sizeof(T) / 2; ++i) {
            const unsigned char t = b[i];
            b[i] = b[sizeof(T) - 1 - i];
            b[sizeof(T) - 1 - i] = t;
        }
    }
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}
}  // namespace detail

// Reads scalarSize(t) bytes at p (no alignment needed) as a double.
[[nodiscard]] inline double loadScalar(const char* p, ScalarType t, bool bigEndian) {
    switch (t) {
        case ScalarType::kInt8: return static_cast<int8_t>(*p);
        case ScalarType::kUInt8: return static_cast<uint8_t>(*p);
        case ScalarType::kInt16: return detail::loadRaw<int16_t>(p, bigEndian);
        case ScalarType::kUInt16: return detail::loadRaw<uint16_t>(p, bigEndian);
        case ScalarType::kInt32: return detail::loadRaw<int32_t>(p, bigEndian);
        case ScalarType::kUInt32: return detail::loadRaw<uint32_t>(p, bigEndian);
        case ScalarType::kInt64: return static_cast<double>(detail::loadRaw<int64_t>(p, bigEndian));
        case ScalarType::kUInt64: return static_cast<double>(detail::loadRaw<uint64_t>(p, bigEndian));
        case ScalarType::kFloat32: return detail::loadRaw<float>(p, bigEndian);
        case ScalarType::kFloat64: return detail::loadRaw<double>(p, bigEndian);
    }
    return 0.0;
}

}  // namespace rthdist::io
