// Label scalar types (label_types.hpp): raw scalars to int32 labels.
#include "masks/label_types.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <type_traits>

namespace rthdist::masks::detail {
namespace {

template <class T>
std::optional<Error> toLabels(const void* raw, size_t n, bool scale, double slope, double inter,
                              const std::string& path, std::vector<int32_t>& out) {
    out.resize(n);
    const T* in = static_cast<const T*>(raw);
    for (size_t i = 0; i < n; ++i) {
        T t;
        std::memcpy(&t, in + i, sizeof(T));
        if constexpr (std::is_integral_v<T>) {
            if (!scale) {
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
                                              std::to_string(i) + " does not fit int32");
                }
            }
        }
        double v = double(t);
        if (scale) v = v * slope + inter;
        if (!(std::isfinite(v) && v == std::floor(v) && v >= -2147483648.0 && v <= 2147483647.0)) {
            char text[64];
            std::snprintf(text, sizeof text, "%.17g", v);
            return badInput(path, std::string("label value ") + text + " at voxel index " +
                                      std::to_string(i) +
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

glm::dmat4 diagonalAffine(glm::dvec3 size) {
    glm::dmat4 m(1.0);
    m[0][0] = size.x;
    m[1][1] = size.y;
    m[2][2] = size.z;
    return m;
}

}  // namespace rthdist::masks::detail
