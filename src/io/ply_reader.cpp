// PLY as specified by Greg Turk's "The PLY Polygon File Format" (1994) and
// implemented by rply/tinyply: a text header of elements and properties, then
// the element bodies in header order, ascii or binary in either byte order.
#include "io/ply_reader.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/scalar_type.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {
namespace {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
    std::string name;
    ScalarType type = ScalarType::kFloat32;  // item type for lists
    bool isList = false;
    ScalarType countType = ScalarType::kUInt8;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    size_t line = 0;
    std::vector<PlyProperty> properties;

    // Fewest bytes one item can take in a binary body (lists may be empty).
    [[nodiscard]] uint64_t minBinaryItemSize() const {
        uint64_t size = 0;
        for (const PlyProperty& p : properties) size += scalarSize(p.isList ? p.countType : p.type);
        return size;
    }
};

struct PlyHeader {
    PlyFormat format = PlyFormat::kAscii;
    std::vector<PlyElement> elements;
    size_t bodyOffset = 0;  // first byte after "end_header\n"
    size_t bodyLine = 0;    // line number of the first body line (ascii)
};

Result<PlyHeader> parseHeader(std::string_view bytes, const std::string& path) {
    PlyHeader header;
    TextCursor cursor(bytes);
    std::string_view line;
    if (!cursor.nextLine(line) || trimBlank(line) != "ply") {
        return badInput(path, lineWhere(1), "not a PLY file (first line is not 'ply')");
    }
    bool haveFormat = false;
    for (;;) {
        if (!cursor.nextLine(line)) return badInput(path, "header", "no 'end_header' line");
        const size_t lineNo = cursor.line();
        std::array<std::string_view, 6> tok{};
        const size_t n = splitTokens(line, tok.data(), tok.size());
        if (n == 0) continue;
        const std::string_view key = tok[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            header.bodyOffset = cursor.offset();
            header.bodyLine = lineNo + 1;
            break;
        }
        if (key == "format") {
            if (n < 2) return badInput(path, lineWhere(lineNo), "format line without a format");
            if (tok[1] == "ascii") {
                header.format = PlyFormat::kAscii;
            } else if (tok[1] == "binary_little_endian") {
                header.format = PlyFormat::kBinaryLittleEndian;
            } else if (tok[1] == "binary_big_endian") {
                header.format = PlyFormat::kBinaryBigEndian;
            } else {
                return badInput(path, lineWhere(lineNo), "unsupported format '" + std::string(tok[1]) + "'");
            }
            if (n >= 3 && tok[2] != "1.0" && tok[2] != "1") {
                return badInput(path, lineWhere(lineNo),
                                "unsupported PLY version '" + std::string(tok[2]) + "'");
            }
            haveFormat = true;
            continue;
        }
        if (key == "element") {
            uint64_t count = 0;
            if (n != 3 || !parseUInt(tok[2], count)) {
                return badInput(path, lineWhere(lineNo),
                                "malformed element line (want 'element <name> <count>')");
            }
            header.elements.push_back(PlyElement{std::string(tok[1]), count, lineNo, {}});
            continue;
        }
        if (key == "property") {
            if (header.elements.empty())
                return badInput(path, lineWhere(lineNo), "property before any element");
            PlyProperty prop;
            if (n >= 2 && tok[1] == "list") {
                if (n != 5) {
                    return badInput(
                        path, lineWhere(lineNo),
                        "malformed list property (want 'property list <count type> <item type> <name>')");
                }
                const auto countType = plyScalarType(tok[2]);
                const auto itemType = plyScalarType(tok[3]);
                if (!countType || !isIntegral(*countType)) {
                    return badInput(path, lineWhere(lineNo),
                                    "unsupported list count type '" + std::string(tok[2]) + "'");
                }
                if (!itemType) {
                    return badInput(path, lineWhere(lineNo),
                                    "unsupported property type '" + std::string(tok[3]) + "'");
                }
                prop = PlyProperty{std::string(tok[4]), *itemType, true, *countType};
            } else {
                if (n != 3) return badInput(path, lineWhere(lineNo), "malformed property line");
                const auto type = plyScalarType(tok[1]);
                if (!type)
                    return badInput(path, lineWhere(lineNo),
                                    "unsupported property type '" + std::string(tok[1]) + "'");
                prop = PlyProperty{std::string(tok[2]), *type, false, ScalarType::kUInt8};
            }
            header.elements.back().properties.push_back(std::move(prop));
            continue;
        }
        return badInput(path, lineWhere(lineNo), "unknown header keyword '" + std::string(key) + "'");
    }
    if (!haveFormat) return badInput(path, "header", "no 'format' line");
    return header;
}

// Index of the vertex element's x, y, z properties.
struct XyzIndex {
    std::array<size_t, 3> prop{};
};

Result<XyzIndex> findXyz(const PlyElement& vertex, const std::string& path) {
    XyzIndex idx;
    constexpr std::array<std::string_view, 3> kNames = {"x", "y", "z"};
    for (size_t axis = 0; axis < 3; ++axis) {
        std::optional<size_t> found;
        for (size_t i = 0; i < vertex.properties.size(); ++i) {
            if (vertex.properties[i].name == kNames[axis]) found = i;
        }
        if (!found) {
            return badInput(path, "element vertex", "no property '" + std::string(kNames[axis]) + "'");
        }
        if (vertex.properties[*found].isList) {
            return badInput(path, "element vertex", "property '" + std::string(kNames[axis]) + "' is a list");
        }
        idx.prop[axis] = *found;
    }
    return idx;
}

// ---- binary bodies ---------------------------------------------------------

class BinaryBody {
public:
    BinaryBody(std::string_view bytes, size_t offset, bool bigEndian, const std::string& path)
        : m_bytes(bytes), m_pos(offset), m_bigEndian(bigEndian), m_path(path) {}

    // Rejects a count the remaining bytes cannot hold, before any allocation.
    std::optional<Error> checkCount(const PlyElement& e) const {
        const uint64_t minSize = e.minBinaryItemSize();
        const uint64_t left = m_bytes.size() - m_pos;
        if (minSize != 0 && e.count > left / minSize) {
            return badInput(m_path, offsetWhere(m_pos),
                            "element " + e.name + " declares " + std::to_string(e.count) +
                                " items of at least " + std::to_string(minSize) + " bytes, but only " +
                                std::to_string(left) + " bytes remain (truncated body or wrong count)");
        }
        return std::nullopt;
    }

    // Walks one item; for the vertex element, values[axis] receives x/y/z.
    std::optional<Error> item(const PlyElement& e, uint64_t index, const XyzIndex* xyz, double* values) {
        for (size_t i = 0; i < e.properties.size(); ++i) {
            const PlyProperty& p = e.properties[i];
            if (!p.isList) {
                const size_t size = scalarSize(p.type);
                if (m_bytes.size() - m_pos < size) return truncated(e, index);
                if (xyz != nullptr) {
                    for (size_t axis = 0; axis < 3; ++axis) {
                        if (xyz->prop[axis] == i)
                            values[axis] = loadScalar(m_bytes.data() + m_pos, p.type, m_bigEndian);
                    }
                }
                m_pos += size;
                continue;
            }
            const size_t countSize = scalarSize(p.countType);
            if (m_bytes.size() - m_pos < countSize) return truncated(e, index);
            const double count = loadScalar(m_bytes.data() + m_pos, p.countType, m_bigEndian);
            if (count < 0) {
                return badInput(
                    m_path, offsetWhere(m_pos),
                    "element " + e.name + " item " + std::to_string(index) + ": negative list length");
            }
            m_pos += countSize;
            const uint64_t skip =
                static_cast<uint64_t>(count) * scalarSize(p.type);  // count < 2^32: no overflow
            if (m_bytes.size() - m_pos < skip) return truncated(e, index);
            m_pos += skip;
        }
        return std::nullopt;
    }

private:
    Error truncated(const PlyElement& e, uint64_t index) const {
        return badInput(m_path, offsetWhere(m_pos),
                        "element " + e.name + " item " + std::to_string(index) +
                            ": file ends inside the item (" + std::to_string(e.count) +
                            " declared; truncated body)");
    }

    std::string_view m_bytes;
    size_t m_pos;
    bool m_bigEndian;
    const std::string& m_path;
};

Result<std::vector<glm::vec3>> readBinaryBody(std::string_view bytes, const PlyHeader& header,
                                              size_t vertexElement, const XyzIndex& xyz,
                                              const std::string& path) {
    BinaryBody body(bytes, header.bodyOffset, header.format == PlyFormat::kBinaryBigEndian, path);
    for (size_t ei = 0; ei < vertexElement; ++ei) {
        const PlyElement& e = header.elements[ei];
        if (auto err = body.checkCount(e)) return *err;
        if (e.properties.empty()) continue;
        for (uint64_t k = 0; k < e.count; ++k) {
            if (auto err = body.item(e, k, nullptr, nullptr)) return *err;
        }
    }
    const PlyElement& vertex = header.elements[vertexElement];
    if (auto err = body.checkCount(vertex)) return *err;
    std::vector<glm::vec3> points(static_cast<size_t>(vertex.count));
    double v[3] = {0, 0, 0};
    for (uint64_t k = 0; k < vertex.count; ++k) {
        if (auto err = body.item(vertex, k, &xyz, v)) return *err;
        points[k] = glm::vec3(narrowToFloat(v[0]), narrowToFloat(v[1]), narrowToFloat(v[2]));
    }
    return points;
}

// ---- ascii bodies ----------------------------------------------------------

Result<std::vector<glm::vec3>> readAsciiBody(std::string_view bytes, const PlyHeader& header,
                                             size_t vertexElement, const XyzIndex& xyz,
                                             const std::string& path) {
    TextCursor cursor(bytes.substr(header.bodyOffset), header.bodyLine);
    auto endOfFile = [&](const PlyElement& e, uint64_t index) {
        return badInput(path, lineWhere(cursor.line()),
                        "file ends inside element " + e.name + " item " + std::to_string(index) + " (" +
                            std::to_string(e.count) + " declared)");
    };
    // Reads a list length token; on failure returns an error.
    auto listLength = [&](const PlyElement& e, uint64_t index, uint64_t& count) -> std::optional<Error> {
        const std::string_view tok = cursor.nextToken();
        if (tok.empty()) return endOfFile(e, index);
        if (!parseUInt(tok, count)) {
            return badInput(path, lineWhere(cursor.line()),
                            "element " + e.name + " item " + std::to_string(index) + ": bad list length '" +
                                std::string(tok) + "'");
        }
        return std::nullopt;
    };

    for (size_t ei = 0; ei < vertexElement; ++ei) {
        const PlyElement& e = header.elements[ei];
        if (e.properties.empty()) continue;
        for (uint64_t k = 0; k < e.count; ++k) {
            for (const PlyProperty& p : e.properties) {
                uint64_t tokens = 1;
                if (p.isList) {
                    if (auto err = listLength(e, k, tokens)) return *err;
                }
                for (uint64_t t = 0; t < tokens; ++t) {
                    if (cursor.nextToken().empty()) return endOfFile(e, k);
                }
            }
        }
    }

    const PlyElement& vertex = header.elements[vertexElement];
    // Every property takes at least one character and one separator.
    const uint64_t minItemChars = 2 * vertex.properties.size();
    if (vertex.count > (cursor.remaining() + 1) / minItemChars) {
        return badInput(path, "element vertex",
                        "declares " + std::to_string(vertex.count) + " vertices but only " +
                            std::to_string(cursor.remaining()) +
                            " bytes remain (truncated body or wrong count)");
    }
    std::vector<glm::vec3> points(static_cast<size_t>(vertex.count));
    for (uint64_t k = 0; k < vertex.count; ++k) {
        float v[3] = {0, 0, 0};
        for (size_t i = 0; i < vertex.properties.size(); ++i) {
            const PlyProperty& p = vertex.properties[i];
            if (p.isList) {
                uint64_t tokens = 0;
                if (auto err = listLength(vertex, k, tokens)) return *err;
                for (uint64_t t = 0; t < tokens; ++t) {
                    if (cursor.nextToken().empty()) return endOfFile(vertex, k);
                }
                continue;
            }
            const std::string_view tok = cursor.nextToken();
            if (tok.empty()) return endOfFile(vertex, k);
            for (size_t axis = 0; axis < 3; ++axis) {
                if (xyz.prop[axis] != i) continue;
                if (!parseFloat(tok, v[axis])) {
                    return badInput(
                        path, lineWhere(cursor.line()),
                        "vertex " + std::to_string(k) + " property " + p.name + ": " + notANumber(tok));
                }
            }
        }
        points[k] = glm::vec3(v[0], v[1], v[2]);
    }
    return points;
}

}  // namespace

Result<std::vector<glm::vec3>> readPly(std::string_view bytes, const std::string& path) {
    auto header = parseHeader(bytes, path);
    if (!header) return header.error();
    size_t vertexElement = header->elements.size();
    for (size_t i = 0; i < header->elements.size(); ++i) {
        if (header->elements[i].name == "vertex") {
            vertexElement = i;
            break;
        }
    }
    if (vertexElement == header->elements.size()) return badInput(path, "header", "no 'vertex' element");
    auto xyz = findXyz(header->elements[vertexElement], path);
    if (!xyz) return xyz.error();
    if (header->format == PlyFormat::kAscii) return readAsciiBody(bytes, *header, vertexElement, *xyz, path);
    return readBinaryBody(bytes, *header, vertexElement, *xyz, path);
}

}  // namespace rthdist::io
