#include "io/stl_reader.hpp"

#include <cstdint>

#include "io/gzip_inflate.hpp"
#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/scalar_type.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {
namespace {

constexpr size_t kHeaderSize = 80;
constexpr size_t kFacetSize = 50;  // normal, 3 vertices (float32 LE), uint16 attribute

PointCloud readBinary(std::string_view bytes, uint64_t facets) {
    PointArray<glm::vec3> points(static_cast<size_t>(facets) * 3, glm::vec3(0.0f));
    const char* p = bytes.data() + kHeaderSize + 4;
    for (uint64_t f = 0; f < facets; ++f, p += kFacetSize) {
        for (size_t c = 0; c < 3; ++c) {
            const char* v = p + 12 + 12 * c;
            points[f * 3 + c] = glm::vec3(static_cast<float>(loadScalar(v, ScalarType::kFloat32, false)),
                                          static_cast<float>(loadScalar(v + 4, ScalarType::kFloat32, false)),
                                          static_cast<float>(loadScalar(v + 8, ScalarType::kFloat32, false)));
        }
    }
    return PointCloud{Scalar::kFloat32, std::move(points), {}};
}

Result<PointCloud> readAscii(std::string_view bytes, const std::string& path) {
    PointArray<glm::dvec3> points;
    TextCursor cursor(bytes);
    for (std::string_view tok = cursor.nextToken(); !tok.empty(); tok = cursor.nextToken()) {
        if (tok != "vertex") continue;
        double v[3];
        for (size_t axis = 0; axis < 3; ++axis) {
            const std::string_view num = cursor.nextToken();
            if (!parseDouble(num, v[axis])) {
                return badInput(path, lineWhere(cursor.line()),
                                num.empty() ? std::string("file ends inside a vertex") : notANumber(num));
            }
        }
        points.emplace_back(v[0], v[1], v[2]);
    }
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

// An ascii STL starts with "solid" and is text; binary STLs have NUL bytes
// in every attribute word (and many also start with "solid").
bool looksAscii(std::string_view bytes) {
    return trimBlank(bytes.substr(bomLength(bytes), 64)).starts_with("solid") &&
           bytes.find('\0') == std::string_view::npos;
}

uint64_t binarySize(std::string_view bytes, uint64_t& facets) {
    facets = static_cast<uint64_t>(loadScalar(bytes.data() + kHeaderSize, ScalarType::kUInt32, false));
    return kHeaderSize + 4 + facets * kFacetSize;
}

}  // namespace

Result<PointCloud> readStl(std::string_view bytes, const std::string& path) {
    // The size decides first (84 + 50 * facets), then the NUL bytes tell a
    // binary STL of the wrong size from an ascii one.
    const bool solid = trimBlank(bytes.substr(bomLength(bytes), 64)).starts_with("solid");
    const bool text = looksAscii(bytes);
    if (bytes.size() >= kHeaderSize + 4) {
        uint64_t facets = 0;
        const uint64_t need = binarySize(bytes, facets);
        if (bytes.size() == need) return readBinary(bytes, facets);
        if (!text) {
            if (bytes.size() < need) {
                return badInput(
                    path, offsetWhere(kHeaderSize),
                    "binary STL declares " + std::to_string(facets) + " facets (" + std::to_string(need) +
                        " bytes) but the file has " + std::to_string(bytes.size()) + " bytes" +
                        (solid ? " (its header starts with 'solid', but the file is not text)" : ""));
            }
            return readBinary(bytes, facets);  // trailing bytes after the facets are ignored
        }
    } else if (!solid) {
        return badInput(path, offsetWhere(0), "neither ascii STL ('solid') nor a complete binary STL header");
    }
    return readAscii(bytes, path);
}

Result<uint64_t> stlInflatedBound(std::string_view head, bool whole, const std::string& path) {
    (void)whole;
    (void)path;
    if (head.size() < kHeaderSize + 4 || looksAscii(head)) return kNoInflatedBound;
    uint64_t facets = 0;
    return binarySize(head, facets);
}

}  // namespace rthdist::io
