// Whether a run of points holds a NaN or an infinity, as one OR over the
// exponent bits with no early exit, so that the loop vectorizes: the
// loaders check whole chunks this way, in the pass that wrote them where
// they can (binary PLY/PCD, LAS), and look for the first bad point only in
// a chunk that has one.
#pragma once

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

#include "io/io_error.hpp"
#include "io/parallel_chunks.hpp"
#include "rthdist/io.hpp"

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

// What a float cloud's error adds: a double beyond the float range was
// rounded to an infinity on the way.
template <class Vec>
[[nodiscard]] constexpr const char* nonFiniteNote() {
    return sizeof(typename Vec::value_type) == 8 ? "" : " (or beyond float range)";
}

// The first point of points[begin, end) with a NaN or infinite coordinate,
// as the error naming it ("vertex i: coordinate y is NaN"); nullopt when
// every coordinate is finite. points[i] is vertex i of the file.
template <class Vec>
[[nodiscard]] std::optional<Error> firstNonFiniteIn(const Vec* points, uint64_t begin, uint64_t end,
                                                    const std::string& path) {
    if (!anyNonFinite(points + begin, static_cast<size_t>(end - begin))) return std::nullopt;
    for (uint64_t i = begin; i < end; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const auto v = points[i][axis];
            if (std::isfinite(v)) continue;
            return badInput(path, "vertex " + std::to_string(i),
                            std::string("coordinate ") + "xyz"[axis] + " is " +
                                (std::isnan(v) ? "NaN" : "infinite") + nonFiniteNote<Vec>());
        }
    }
    return std::nullopt;
}

// The same over a whole array, in parallel chunks (the lowest chunk's first
// is the first): for the readers that do not check as they write.
template <class Vec>
[[nodiscard]] std::optional<Error> firstNonFinite(const Vec* points, size_t count, const std::string& path,
                                                  const ChunkPlan& plan) {
    const uint64_t perChunk = plan.items(sizeof(Vec));
    return forEachChunk(chunkCount(count, perChunk), plan, [&](size_t c) -> std::optional<Error> {
        return firstNonFiniteIn(points, c * perChunk, std::min<uint64_t>(count, (c + 1) * perChunk), path);
    });
}

// A whole cloud, in its precision.
[[nodiscard]] inline std::optional<Error> checkFiniteCloud(const PointCloud& cloud, const std::string& path,
                                                           const ChunkPlan& plan) {
    return cloud.scalar == Scalar::kFloat64
               ? firstNonFinite(cloud.doubles.data(), cloud.doubles.size(), path, plan)
               : firstNonFinite(cloud.floats.data(), cloud.floats.size(), path, plan);
}

}  // namespace rthdist::io
