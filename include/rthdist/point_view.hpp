// rthdist — the input type: a read-only view of 3-D points in float or
// double, interleaved with a byte stride, so vertex buffers (position with
// normals, colours...) and NumPy (N,3) or (N,k) arrays and their slices are
// read where they are, without a copy on the caller's side.
//
// Point i's x, y, z are three consecutive scalars starting at
// data + i * strideBytes. strideBytes must be at least 3 scalars (12 bytes for
// float, 24 for double) and a multiple of the scalar size; the view must stay
// valid for the duration of the call that reads it.
//
// Precision: double views keep their precision (design.md §8): the engine
// searches in float32 after shifting both sets by one origin chosen in
// double, and reports witnesses and distances from the original doubles.
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace rthdist {

enum class Scalar : uint8_t { kFloat32, kFloat64 };

[[nodiscard]] constexpr size_t scalarBytes(Scalar s) { return s == Scalar::kFloat64 ? 8 : 4; }

struct PointView {
    const void* data = nullptr;
    size_t count = 0;
    size_t strideBytes = 12;
    Scalar scalar = Scalar::kFloat32;

    PointView() = default;
    // Implicit from the containers earlier releases took (old calls keep working).
    PointView(std::span<const glm::vec3> p)
        : data(p.data()), count(p.size()), strideBytes(sizeof(glm::vec3)) {}
    PointView(const std::vector<glm::vec3>& p) : PointView(std::span<const glm::vec3>(p)) {}
    PointView(std::span<const glm::dvec3> p)
        : data(p.data()), count(p.size()), strideBytes(sizeof(glm::dvec3)), scalar(Scalar::kFloat64) {}
    PointView(const std::vector<glm::dvec3>& p) : PointView(std::span<const glm::dvec3>(p)) {}

    // count points of three floats (or doubles), strideBytes apart
    // (0 = packed: three scalars per point).
    [[nodiscard]] static PointView floats(const float* xyz, size_t count, size_t strideBytes = 0) {
        return make(xyz, count, strideBytes, Scalar::kFloat32);
    }
    [[nodiscard]] static PointView doubles(const double* xyz, size_t count, size_t strideBytes = 0) {
        return make(xyz, count, strideBytes, Scalar::kFloat64);
    }

    [[nodiscard]] size_t size() const { return count; }
    [[nodiscard]] bool empty() const { return count == 0; }
    // True when the points are packed float triples (readable as glm::vec3).
    [[nodiscard]] bool packedFloat() const { return scalar == Scalar::kFloat32 && strideBytes == 12; }
    // Point i in double (exact for float views too).
    [[nodiscard]] glm::dvec3 at(size_t i) const {
        const char* p = static_cast<const char*>(data) + i * strideBytes;
        if (scalar == Scalar::kFloat64) {
            double v[3];
            std::memcpy(v, p, sizeof(v));
            return {v[0], v[1], v[2]};
        }
        float v[3];
        std::memcpy(v, p, sizeof(v));
        return {v[0], v[1], v[2]};
    }

private:
    static PointView make(const void* xyz, size_t count, size_t strideBytes, Scalar scalar) {
        PointView v;
        v.data = xyz;
        v.count = count;
        v.scalar = scalar;
        v.strideBytes = strideBytes == 0 ? 3 * scalarBytes(scalar) : strideBytes;
        return v;
    }
};

}  // namespace rthdist
