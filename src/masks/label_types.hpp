// The scalar types a label volume may hold and their conversion to int32
// labels, shared by the NumPy reader and arrays (volume.cpp) and the NIfTI
// reader (nifti.cpp, which alone needs libnifti2).
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::masks::detail {

// Converts n raw scalars (scaled by slope/inter when `scale`) to int32
// labels; a non-integral or out-of-range value is an error naming the voxel
// and `path`.
using ToLabels = std::optional<Error> (*)(const void* raw, size_t n, bool scale, double slope, double inter,
                                          const std::string& path, std::vector<int32_t>& out);

// A label scalar type: its NumPy kind (dtype without byte order), size and conversion.
struct LabelType {
    std::string_view npyKind;
    size_t bytes;
    ToLabels toLabels;
};

// The type of NumPy kind "u1", "i1", "u2", "i2", "u4", "i4", "u8", "i8",
// "f4" or "f8" ("b1" reads as "u1"); null for any other.
[[nodiscard]] const LabelType* labelType(std::string_view npyKind);

// kBadInput "<path>: <what>".
[[nodiscard]] Error badInput(const std::string& path, const std::string& what);

// Voxel size along i, j, k, origin 0.
[[nodiscard]] glm::dmat4 diagonalAffine(glm::dvec3 size);

}  // namespace rthdist::masks::detail
