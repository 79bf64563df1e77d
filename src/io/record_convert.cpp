#include "io/record_convert.hpp"

#include <cstring>
#include <type_traits>

#include "io/non_finite.hpp"
#include "io/number_parse.hpp"

namespace rthdist::io {
namespace {

template <size_t kSize>
using Bits = std::conditional_t<kSize == 2, uint16_t, std::conditional_t<kSize == 4, uint32_t, uint64_t>>;

// The T stored at p in the file's byte order (kSwap: not the machine's).
template <class T, bool kSwap>
T loadAs(const char* p) {
    T v;
    if constexpr (!kSwap || sizeof(T) == 1) {
        std::memcpy(&v, p, sizeof(T));
    } else {
        Bits<sizeof(T)> u;
        std::memcpy(&u, p, sizeof(T));
        if constexpr (sizeof(T) == 2) u = __builtin_bswap16(u);
        if constexpr (sizeof(T) == 4) u = __builtin_bswap32(u);
        if constexpr (sizeof(T) == 8) u = __builtin_bswap64(u);
        std::memcpy(&v, &u, sizeof(T));
    }
    return v;
}

// One coordinate in the cloud's precision, as loadScalar + narrowToFloat give it.
template <class Vec, class T>
typename Vec::value_type toCoordinate(T v) {
    if constexpr (std::is_same_v<typename Vec::value_type, double> || std::is_same_v<T, float>) {
        return static_cast<typename Vec::value_type>(v);
    } else {
        return narrowToFloat(static_cast<double>(v));
    }
}

// Records [begin, end) whose three coordinates are all of type T.
template <class T, bool kSwap, class Vec>
void convertSame(const RecordLayout& l, uint64_t begin, uint64_t end, Vec* out) {
    const char* p = l.first + begin * l.stride;
    const size_t ox = l.offset[0], oy = l.offset[1], oz = l.offset[2];
    for (uint64_t k = begin; k < end; ++k, p += l.stride) {
        out[k] = Vec(toCoordinate<Vec>(loadAs<T, kSwap>(p + ox)), toCoordinate<Vec>(loadAs<T, kSwap>(p + oy)),
                     toCoordinate<Vec>(loadAs<T, kSwap>(p + oz)));
    }
}

// Any mix of types: one loadScalar per value.
template <class Vec>
void convertMixed(const RecordLayout& l, uint64_t begin, uint64_t end, Vec* out) {
    const char* p = l.first + begin * l.stride;
    for (uint64_t k = begin; k < end; ++k, p += l.stride) {
        double v[3];
        for (size_t axis = 0; axis < 3; ++axis)
            v[axis] = loadScalar(p + l.offset[axis], l.type[axis], l.bigEndian);
        out[k] = Vec(toCoordinate<Vec>(v[0]), toCoordinate<Vec>(v[1]), toCoordinate<Vec>(v[2]));
    }
}

template <bool kSwap, class Vec>
void convertRange(const RecordLayout& l, uint64_t begin, uint64_t end, Vec* out) {
    if (l.type[0] != l.type[1] || l.type[0] != l.type[2]) return convertMixed(l, begin, end, out);
    switch (l.type[0]) {
        case ScalarType::kInt8: return convertSame<int8_t, kSwap>(l, begin, end, out);
        case ScalarType::kUInt8: return convertSame<uint8_t, kSwap>(l, begin, end, out);
        case ScalarType::kInt16: return convertSame<int16_t, kSwap>(l, begin, end, out);
        case ScalarType::kUInt16: return convertSame<uint16_t, kSwap>(l, begin, end, out);
        case ScalarType::kInt32: return convertSame<int32_t, kSwap>(l, begin, end, out);
        case ScalarType::kUInt32: return convertSame<uint32_t, kSwap>(l, begin, end, out);
        case ScalarType::kInt64: return convertSame<int64_t, kSwap>(l, begin, end, out);
        case ScalarType::kUInt64: return convertSame<uint64_t, kSwap>(l, begin, end, out);
        case ScalarType::kFloat32: return convertSame<float, kSwap>(l, begin, end, out);
        case ScalarType::kFloat64: return convertSame<double, kSwap>(l, begin, end, out);
    }
}

template <class Vec>
std::optional<Error> convertAll(const RecordLayout& l, Vec* out, const ChunkPlan& plan,
                                const std::string& path) {
    const uint64_t perChunk = plan.items(l.stride);
    const size_t chunks = chunkCount(l.count, perChunk);
    const bool swap = l.bigEndian != (std::endian::native == std::endian::big);
    return forEachChunk(chunks, plan, [&](size_t c) -> std::optional<Error> {
        const uint64_t begin = c * perChunk;
        const uint64_t end = std::min(l.count, begin + perChunk);
        if (swap) {
            convertRange<true>(l, begin, end, out);
        } else {
            convertRange<false>(l, begin, end, out);
        }
        return firstNonFiniteIn(out, begin, end, path);
    });
}

}  // namespace

std::optional<Error> convertRecords(const RecordLayout& layout, glm::vec3* out, const ChunkPlan& plan,
                                    const std::string& path) {
    return convertAll(layout, out, plan, path);
}

std::optional<Error> convertRecords(const RecordLayout& layout, glm::dvec3* out, const ChunkPlan& plan,
                                    const std::string& path) {
    return convertAll(layout, out, plan, path);
}

}  // namespace rthdist::io
