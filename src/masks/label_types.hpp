// The scalar types a label volume may hold and their conversion to int32
// labels, shared by the NumPy reader and arrays (volume.cpp) and the NIfTI
// reader (nifti.cpp, which alone needs libnifti2).
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::masks {
struct Volume;
}

namespace rthdist::masks::detail {

// How raw scalars become labels: byte order and the NIfTI scaling.
struct LabelScale {
    bool swap = false;   // the scalars are in the other byte order
    bool scale = false;  // value * slope + inter
    double slope = 1.0, inter = 0.0;
};

// Converts n raw scalars at `raw` to int32 labels at `out` (n of them); a
// NaN, non-integral or out-of-range value is an error naming `path` and the
// voxel index (firstIndex + its position).
using ToLabels = std::optional<Error> (*)(const void* raw, size_t n, const LabelScale& how,
                                          const std::string& path, uint64_t firstIndex, int32_t* out);

// A label scalar type: its NumPy kind (dtype without byte order), size and conversion.
struct LabelType {
    std::string_view npyKind;
    size_t bytes;
    ToLabels toLabels;
};

// The type of NumPy kind "u1", "i1", "u2", "i2", "u4", "i4", "u8", "i8",
// "f4" or "f8" ("b1" reads as "u1"); null for any other.
[[nodiscard]] const LabelType* labelType(std::string_view npyKind);

// The labels of a 3-D array of `type` whose raw scalars `next(bytes)` hands
// out in file order (C order, or Fortran when `fortran`) into v, i fastest,
// a piece (4 M voxels) at a time: bool and uint8 (unscaled) into
// v.labels8, the others converted into v.labels (volume.cpp).
[[nodiscard]] std::optional<Error> readVolumeLabels(const std::function<Result<const char*>(size_t)>& next,
                                                    const std::array<int64_t, 3>& dims, bool fortran,
                                                    const LabelType& type, const LabelScale& how,
                                                    const std::string& path, Volume& v);

// kBadInput "<path>: <what>".
[[nodiscard]] Error badInput(const std::string& path, const std::string& what);

// Voxel size along i, j, k, origin 0.
[[nodiscard]] glm::dmat4 diagonalAffine(glm::dvec3 size);

// The geometry rules of masks.hpp (kMinSpacing, kMaxCoordinate, finite,
// last row 0 0 0 1, not singular) for a grid of `dims` with voxel-to-world
// `m`: the error `code` "<name>: <field> ..." naming the limit.
[[nodiscard]] std::optional<Error> checkGrid(const std::array<int64_t, 3>& dims, const glm::dmat4& m,
                                             const std::string& name, const std::string& field,
                                             ErrorCode code);

// kBadInput when `voxels` voxels of `fileBytes` bytes each in the file,
// held as `heldBytes` each, exceed maxVolumeBytes; `what` names the type.
[[nodiscard]] std::optional<Error> checkVolumeBytes(const std::string& path, uint64_t voxels,
                                                    size_t fileBytes, size_t heldBytes,
                                                    const std::string& what, uint64_t maxVolumeBytes);

}  // namespace rthdist::masks::detail
