// Label scalar types (label_types.hpp): raw scalars to int32 labels.
#include "masks/label_types.hpp"

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <type_traits>

#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {
namespace {

template <class T>
T swapped(T t) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &t, sizeof(T));
    std::reverse(b, b + sizeof(T));
    std::memcpy(&t, b, sizeof(T));
    return t;
}

template <class T>
std::optional<Error> toLabels(const void* raw, size_t n, const LabelScale& how, const std::string& path,
                              uint64_t firstIndex, int32_t* out) {
    const unsigned char* in = static_cast<const unsigned char*>(raw);
    for (size_t i = 0; i < n; ++i) {
        T t;
        std::memcpy(&t, in + i * sizeof(T), sizeof(T));
        if constexpr (sizeof(T) > 1) {
            if (how.swap) t = swapped(t);
        }
        if constexpr (std::is_integral_v<T>) {
            if (!how.scale) {
                if constexpr (sizeof(T) < 4 || (sizeof(T) == 4 && std::is_signed_v<T>)) {
                    out[i] = int32_t(t);
                    continue;
                } else {
                    if (t <= T(std::numeric_limits<int32_t>::max()) &&
                        (!std::is_signed_v<T> || int64_t(t) >= std::numeric_limits<int32_t>::min())) {
                        out[i] = int32_t(t);
                        continue;
                    }
                    return badInput(path, "label " + std::to_string(t) + " at voxel index " +
                                              std::to_string(firstIndex + i) + " does not fit int32");
                }
            }
        }
        double v = double(t);
        if (how.scale) v = v * how.slope + how.inter;
        if (!(std::isfinite(v) && v == std::floor(v) && v >= -2147483648.0 && v <= 2147483647.0)) {
            char text[64];
            std::snprintf(text, sizeof text, "%.17g", v);
            return badInput(path, std::string("label value ") + text + " at voxel index " +
                                      std::to_string(firstIndex + i) +
                                      " is not an int32 integer (threshold or round probability maps first)");
        }
        out[i] = int32_t(v);
    }
    return std::nullopt;
}

constexpr LabelType kLabelTypes[] = {
    {"u1", 1, &toLabels<uint8_t>},  {"i1", 1, &toLabels<int8_t>},   {"u2", 2, &toLabels<uint16_t>},
    {"i2", 2, &toLabels<int16_t>},  {"u4", 4, &toLabels<uint32_t>}, {"i4", 4, &toLabels<int32_t>},
    {"u8", 8, &toLabels<uint64_t>}, {"i8", 8, &toLabels<int64_t>},  {"f4", 4, &toLabels<float>},
    {"f8", 8, &toLabels<double>},
};

}  // namespace

const LabelType* labelType(std::string_view kind) {
    if (kind == "b1") kind = "u1";
    for (const LabelType& t : kLabelTypes)
        if (t.npyKind == kind) return &t;
    return nullptr;
}

Error badInput(const std::string& path, const std::string& what) {
    return Error{ErrorCode::kBadInput, path + ": " + what};
}

std::optional<Error> checkGrid(const std::array<int64_t, 3>& dims, const glm::dmat4& m,
                               const std::string& name, const std::string& field, ErrorCode code) {
    auto fail = [&](const std::string& what) { return Error{code, name + ": " + field + " " + what}; };
    auto text = [](double v) {
        char t[40];
        std::snprintf(t, sizeof t, "%.9g", v);
        return std::string(t);
    };
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r]))
                return fail(std::string(c == 3 && r < 3 ? "has a NaN or infinite origin"
                                                        : "has a NaN or infinite entry") +
                            " (row " + std::to_string(r) + ", column " + std::to_string(c) + ")");
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
        return fail("has a last row other than 0 0 0 1");
    double extent = 0.0;
    for (int a = 0; a < 3; ++a) {
        const double s = glm::length(glm::dvec3(m[a]));
        const std::string axis = "voxel axis " + std::to_string(a) + " (spacing " + text(s) + " mm)";
        if (!(s >= kMinSpacing))
            return fail("gives " + axis + " below the smallest spacing rthdist computes exactly, " +
                        text(kMinSpacing) + " mm");
        if (!(s <= kMaxCoordinate) || !(s * double(dims[a]) <= kMaxCoordinate))
            return fail("gives " + axis + " times " + std::to_string(dims[a]) +
                        " voxels beyond the largest extent rthdist computes exactly, " +
                        text(kMaxCoordinate) + " mm");
        extent = std::max(extent, s * double(dims[a]));
    }
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec4 index(corner & 1 ? double(dims[0] - 1) : 0.0, corner & 2 ? double(dims[1] - 1) : 0.0,
                               corner & 4 ? double(dims[2] - 1) : 0.0, 1.0);
        const glm::dvec4 w = m * index;
        for (int r = 0; r < 3; ++r)
            if (!(std::fabs(w[r]) <= kMaxCoordinate))
                return fail("puts voxel (" + text(index.x) + ", " + text(index.y) + ", " + text(index.z) +
                            ") at world coordinate " + text(w[r]) + ", beyond +-" + text(kMaxCoordinate) +
                            " mm, the largest rthdist computes exactly");
    }
    if (glm::determinant(glm::dmat3(m)) == 0.0) return fail("is singular (a voxel axis of length 0)");
    return std::nullopt;
}

std::optional<Error> checkVolumeBytes(const std::string& path, uint64_t voxels, size_t fileBytes,
                                      size_t heldBytes, const std::string& what, uint64_t maxVolumeBytes) {
    const uint64_t limitVoxels = maxVolumeBytes / std::max(fileBytes, heldBytes);
    if (voxels <= limitVoxels) return std::nullopt;
    const long double file = (long double)voxels * fileBytes, held = (long double)voxels * heldBytes;
    char text[320];
    std::snprintf(text, sizeof text,
                  "%llu voxels of %s are %.0Lf bytes in the file and %.0Lf held, beyond the volume limit of "
                  "%llu bytes (%.6g MiB; raise it with --max-volume-mib, VolumeLimits::maxVolumeBytes)",
                  (unsigned long long)voxels, what.c_str(), file, held, (unsigned long long)maxVolumeBytes,
                  double(maxVolumeBytes) / 1048576.0);
    return badInput(path, text);
}

glm::dmat4 diagonalAffine(glm::dvec3 size) {
    glm::dmat4 m(1.0);
    m[0][0] = size.x;
    m[1][1] = size.y;
    m[2][2] = size.z;
    return m;
}

}  // namespace rthdist::masks::detail
