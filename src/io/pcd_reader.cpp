// PCD v0.7 as documented by the Point Cloud Library ("The PCD (Point Cloud
// Data) file format"): a text header, then ascii rows or packed binary rows.
#include "io/pcd_reader.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/scalar_type.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {
namespace {

struct PcdField {
    std::string name;
    size_t size = 4;
    char type = 'F';
    uint64_t count = 1;
    ScalarType scalar = ScalarType::kFloat32;
};

std::optional<ScalarType> pcdScalarType(char type, size_t size) {
    if (type == 'F' && size == 4) return ScalarType::kFloat32;
    if (type == 'F' && size == 8) return ScalarType::kFloat64;
    if (type == 'I' && size == 1) return ScalarType::kInt8;
    if (type == 'I' && size == 2) return ScalarType::kInt16;
    if (type == 'I' && size == 4) return ScalarType::kInt32;
    if (type == 'I' && size == 8) return ScalarType::kInt64;
    if (type == 'U' && size == 1) return ScalarType::kUInt8;
    if (type == 'U' && size == 2) return ScalarType::kUInt16;
    if (type == 'U' && size == 4) return ScalarType::kUInt32;
    if (type == 'U' && size == 8) return ScalarType::kUInt64;
    return std::nullopt;
}

}  // namespace

Result<PointCloud> readPcd(std::string_view bytes, const std::string& path) {
    TextCursor cursor(bytes);
    std::vector<PcdField> fields;
    std::optional<uint64_t> points;
    uint64_t width = 0;
    uint64_t height = 1;
    std::string data;
    size_t dataLine = 0;
    std::string_view line;
    // Headers have a handful of fields in practice; 4096 bounds the work
    // (refilled per line, only the first n are read).
    std::array<std::string_view, 4096> headerTok{};
    while (data.empty()) {
        if (!cursor.nextLine(line)) return badInput(path, "header", "no DATA line");
        const size_t lineNo = cursor.line();
        const std::string_view body = trimBlank(line);
        if (body.empty() || body.front() == '#') continue;
        auto& tok = headerTok;
        const size_t n = splitTokens(body, tok.data(), tok.size());
        if (n > tok.size()) return badInput(path, lineWhere(lineNo), "too many header values");
        const std::string_view key = tok[0];
        auto where = lineWhere(lineNo);
        auto perField = [&](const char* what) -> std::optional<Error> {
            if (n - 1 != fields.size()) {
                return badInput(path, where,
                                std::string(what) + " has " + std::to_string(n - 1) + " values for " +
                                    std::to_string(fields.size()) + " fields");
            }
            return std::nullopt;
        };
        if (key == "VERSION" || key == "VIEWPOINT") continue;
        if (key == "FIELDS" || key == "COLUMNS") {
            fields.clear();
            for (size_t i = 1; i < n; ++i) fields.push_back(PcdField{std::string(tok[i])});
        } else if (key == "SIZE") {
            if (auto err = perField("SIZE")) return *err;
            for (size_t i = 1; i < n; ++i) {
                uint64_t s = 0;
                if (!parseUInt(tok[i], s) || s == 0 || s > 8)
                    return badInput(path, where, "bad SIZE '" + std::string(tok[i]) + "'");
                fields[i - 1].size = static_cast<size_t>(s);
            }
        } else if (key == "TYPE") {
            if (auto err = perField("TYPE")) return *err;
            for (size_t i = 1; i < n; ++i) {
                if (tok[i].size() != 1)
                    return badInput(path, where, "bad TYPE '" + std::string(tok[i]) + "'");
                fields[i - 1].type = tok[i][0];
            }
        } else if (key == "COUNT") {
            if (auto err = perField("COUNT")) return *err;
            for (size_t i = 1; i < n; ++i) {
                uint64_t c = 0;
                if (!parseUInt(tok[i], c) || c == 0 || c > 1'000'000) {
                    return badInput(path, where, "bad COUNT '" + std::string(tok[i]) + "'");
                }
                fields[i - 1].count = c;
            }
        } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
            uint64_t v = 0;
            if (n != 2 || !parseUInt(tok[1], v))
                return badInput(path, where, "bad " + std::string(key) + " line");
            if (key == "WIDTH") width = v;
            if (key == "HEIGHT") height = v;
            if (key == "POINTS") points = v;
        } else if (key == "DATA") {
            if (n != 2) return badInput(path, where, "bad DATA line");
            data = std::string(tok[1]);
            dataLine = lineNo;
        } else {
            return badInput(path, where, "unknown header keyword '" + std::string(key) + "'");
        }
    }
    if (data != "ascii" && data != "binary") {
        return badInput(path, lineWhere(dataLine), "unsupported DATA '" + data + "' (ascii or binary only)");
    }
    if (!points) {
        if (height != 0 && width > UINT64_MAX / height)
            return badInput(path, "header", "WIDTH * HEIGHT overflows");
        points = width * height;
    }

    // Column of x, y, z (first element of each) and bytes/values per row.
    std::array<std::optional<uint64_t>, 3> column{};  // ascii value index
    std::array<uint64_t, 3> byteOffset{};             // binary byte offset
    std::array<ScalarType, 3> scalar{};
    uint64_t valuesPerRow = 0;
    uint64_t bytesPerRow = 0;
    constexpr std::array<std::string_view, 3> kNames = {"x", "y", "z"};
    for (const PcdField& f : fields) {
        const auto type = pcdScalarType(f.type, f.size);
        if (!type) {
            return badInput(
                path, "field " + f.name,
                "unsupported TYPE " + std::string(1, f.type) + " with SIZE " + std::to_string(f.size));
        }
        for (size_t axis = 0; axis < 3; ++axis) {
            if (f.name == kNames[axis] && !column[axis]) {
                column[axis] = valuesPerRow;
                byteOffset[axis] = bytesPerRow;
                scalar[axis] = *type;
            }
        }
        valuesPerRow += f.count;
        bytesPerRow += f.count * f.size;
    }
    for (size_t axis = 0; axis < 3; ++axis) {
        if (!column[axis]) return badInput(path, "header", "no field '" + std::string(kNames[axis]) + "'");
    }

    if (*points == 0) return PointCloud{};
    const uint64_t left = cursor.remaining();
    if (data == "binary") {
        if (*points > left / bytesPerRow) {
            return badInput(path, offsetWhere(cursor.offset()),
                            "declares " + std::to_string(*points) + " points of " +
                                std::to_string(bytesPerRow) + " bytes, but only " + std::to_string(left) +
                                " bytes remain (truncated body or wrong count)");
        }
        PointCloud out;
        out.scalar =
            std::any_of(scalar.begin(), scalar.end(), needsDouble) ? Scalar::kFloat64 : Scalar::kFloat32;
        if (out.scalar == Scalar::kFloat64) {
            out.doubles.resize(static_cast<size_t>(*points));
        } else {
            out.floats.resize(static_cast<size_t>(*points));
        }
        const char* row = bytes.data() + cursor.offset();
        for (uint64_t k = 0; k < *points; ++k, row += bytesPerRow) {
            double v[3];
            for (size_t axis = 0; axis < 3; ++axis)
                v[axis] = loadScalar(row + byteOffset[axis], scalar[axis], false);
            if (out.scalar == Scalar::kFloat64) {
                out.doubles[k] = glm::dvec3(v[0], v[1], v[2]);
            } else {
                out.floats[k] = glm::vec3(narrowToFloat(v[0]), narrowToFloat(v[1]), narrowToFloat(v[2]));
            }
        }
        return out;
    }

    // ascii: one row per line; every value is at least one char and a separator.
    if (*points > (left + 1) / (2 * valuesPerRow)) {
        return badInput(path, lineWhere(dataLine),
                        "declares " + std::to_string(*points) + " points but only " + std::to_string(left) +
                            " bytes follow (truncated body or wrong count)");
    }
    std::vector<glm::dvec3> out(static_cast<size_t>(*points));
    const uint64_t lastColumn = std::max({*column[0], *column[1], *column[2]});
    std::vector<std::string_view> tok(static_cast<size_t>(lastColumn + 1));
    for (uint64_t k = 0; k < *points;) {
        if (!cursor.nextLine(line)) {
            return badInput(path, lineWhere(cursor.line() + 1),
                            "file ends at point " + std::to_string(k) + " of " + std::to_string(*points));
        }
        if (trimBlank(line).empty()) continue;
        const size_t n = splitTokens(line, tok.data(), tok.size());
        if (n < valuesPerRow) {
            return badInput(
                path, lineWhere(cursor.line()),
                "row has " + std::to_string(n) + " values, fields need " + std::to_string(valuesPerRow));
        }
        double v[3];
        for (size_t axis = 0; axis < 3; ++axis) {
            const std::string_view t = tok[static_cast<size_t>(*column[axis])];
            if (!parseDouble(t, v[axis])) {
                return badInput(path, lineWhere(cursor.line()), notANumber(t));
            }
        }
        out[k] = glm::dvec3(v[0], v[1], v[2]);
        ++k;
    }
    return PointCloud{Scalar::kFloat64, {}, std::move(out)};
}

}  // namespace rthdist::io
