// The triangles of a mesh file as its reader finds its faces: each polygon
// checked against the vertex count (the error names the face and its place)
// and fan-triangulated (i0 i1 i2, i0 i2 i3, ...), degenerate ones kept.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/io_error.hpp"

namespace rthdist::io {

class FaceList {
public:
    explicit FaceList(uint64_t vertexCount) : m_vertexCount(vertexCount) {}

    // Polygon number `face` (0-based, in file order), whose place in the file
    // is `where` ("line 12", "byte offset 96"): its vertex indices, 0-based
    // (negative: invalid). The error for an index out of range or a face of
    // fewer than 3 vertices.
    [[nodiscard]] std::optional<Error> addPolygon(std::string_view path, std::string_view where,
                                                  uint64_t face, const std::vector<int64_t>& polygon) {
        if (polygon.size() < 3) {
            return badInput(path, where,
                            "face " + std::to_string(face) + " has " + std::to_string(polygon.size()) +
                                " vertices (a face needs at least 3)");
        }
        for (int64_t v : polygon) {
            if (v < 0 || uint64_t(v) >= m_vertexCount) {
                return badInput(path, where,
                                "face " + std::to_string(face) + ": vertex index " + std::to_string(v) +
                                    " out of range (" + std::to_string(m_vertexCount) + " vertices)");
            }
        }
        for (size_t k = 1; k + 1 < polygon.size(); ++k) {
            m_indices.push_back(uint32_t(polygon[0]));
            m_indices.push_back(uint32_t(polygon[k]));
            m_indices.push_back(uint32_t(polygon[k + 1]));
        }
        return std::nullopt;
    }

    [[nodiscard]] std::vector<uint32_t> take() { return std::move(m_indices); }

private:
    uint64_t m_vertexCount;
    std::vector<uint32_t> m_indices;
};

}  // namespace rthdist::io
