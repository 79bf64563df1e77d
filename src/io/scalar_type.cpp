#include "io/scalar_type.hpp"

namespace rthdist::io {

std::optional<ScalarType> plyScalarType(std::string_view name) {
    struct Entry {
        std::string_view name;
        ScalarType type;
    };
    static constexpr Entry kTable[] = {
        {"char", ScalarType::kInt8},      {"int8", ScalarType::kInt8},
        {"uchar", ScalarType::kUInt8},    {"uint8", ScalarType::kUInt8},
        {"short", ScalarType::kInt16},    {"int16", ScalarType::kInt16},
        {"ushort", ScalarType::kUInt16},  {"uint16", ScalarType::kUInt16},
        {"int", ScalarType::kInt32},      {"int32", ScalarType::kInt32},
        {"uint", ScalarType::kUInt32},    {"uint32", ScalarType::kUInt32},
        {"float", ScalarType::kFloat32},  {"float32", ScalarType::kFloat32},
        {"double", ScalarType::kFloat64}, {"float64", ScalarType::kFloat64},
    };
    for (const Entry& e : kTable) {
        if (e.name == name) return e.type;
    }
    return std::nullopt;
}

}  // namespace rthdist::io
