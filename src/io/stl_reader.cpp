#include "io/stl_reader.hpp"

#include <array>
#include <cstdint>
#include <string>

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

// Line by line: "facet" opens a facet, "vertex x y z" adds its next
// corner, "endfacet" closes it with exactly three (a mesh's triangle t is
// facet t's corners: one of two or four would shift every triangle after
// it); a vertex outside a facet, a fourth vertex and a file that ends
// inside a facet (truncated) are refused, naming the facet and the line.
// The solid's name (the rest of a "solid" or "endsolid" line) and other
// lines ("outer loop", "endloop", an exporter's own keywords) are not read.
Result<PointCloud> readAscii(std::string_view bytes, const std::string& path) {
    PointArray<glm::dvec3> points;
    TextCursor cursor(bytes);
    std::string_view line;
    std::array<std::string_view, 5> tok{};
    uint64_t facet = 0;   // facets opened so far
    int corners = -1;     // of the open facet; -1: none open
    size_t openedAt = 0;  // its "facet" line
    auto facetName = [&facet] { return "facet " + std::to_string(facet - 1); };
    while (cursor.nextLine(line)) {
        const size_t n = splitTokens(trimBlank(line), tok.data(), tok.size());
        if (n == 0) continue;
        const std::string_view key = tok[0];
        if (key == "facet") {
            if (corners >= 0)
                return badInput(path, lineWhere(cursor.line()),
                                facetName() + " (line " + std::to_string(openedAt) + ") has no endfacet");
            ++facet;
            corners = 0;
            openedAt = cursor.line();
        } else if (key == "vertex") {
            if (corners < 0) return badInput(path, lineWhere(cursor.line()), "a vertex outside any facet");
            if (corners == 3)
                return badInput(path, lineWhere(cursor.line()),
                                facetName() + " has more than 3 vertices (an STL facet is a triangle)");
            if (n < 4)
                return badInput(path, lineWhere(cursor.line()),
                                "a vertex line with " + std::to_string(n - 1) + " values (x y z)");
            double v[3];
            for (size_t axis = 0; axis < 3; ++axis)
                if (!parseDouble(tok[axis + 1], v[axis]))
                    return badInput(path, lineWhere(cursor.line()), notANumber(tok[axis + 1]));
            if (n > 4)
                return badInput(path, lineWhere(cursor.line()),
                                "a vertex line with " + std::to_string(n - 1) + " values (x y z)");
            points.emplace_back(v[0], v[1], v[2]);
            ++corners;
        } else if (key == "endfacet") {
            if (corners < 0) return badInput(path, lineWhere(cursor.line()), "endfacet outside any facet");
            if (corners != 3)
                return badInput(path, lineWhere(cursor.line()),
                                facetName() + " has " + std::to_string(corners) +
                                    " vertices (an STL facet is a triangle)");
            corners = -1;
        } else if (key == "endsolid" || key == "solid") {
            if (corners >= 0)
                return badInput(path, lineWhere(cursor.line()),
                                facetName() + " (line " + std::to_string(openedAt) + ") has no endfacet");
        }
    }
    if (corners >= 0)
        return badInput(
            path, lineWhere(cursor.line()),
            "file ends inside " + facetName() + " (line " + std::to_string(openedAt) + "): truncated");
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
            // Trailing bytes after the facets: fewer than a facet's 50 are
            // padding; more could be facets the count leaves out.
            if (bytes.size() - need >= kFacetSize)
                return badInput(path, offsetWhere(kHeaderSize),
                                "binary STL declares " + std::to_string(facets) + " facets (" +
                                    std::to_string(need) + " bytes) but the file has " +
                                    std::to_string(bytes.size()) +
                                    " bytes: " + std::to_string((bytes.size() - need) / kFacetSize) +
                                    " more facets' worth follow the declared ones");
            return readBinary(bytes, facets);
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
