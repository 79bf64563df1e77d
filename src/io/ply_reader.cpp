// PLY as specified by Greg Turk's "The PLY Polygon File Format" (1994) and
// implemented by rply/tinyply: a text header of elements and properties, then
// the element bodies in header order, ascii or binary in either byte order.
#include "io/ply_reader.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "io/face_list.hpp"
#include "io/gzip_inflate.hpp"
#include "io/io_error.hpp"
#include "io/non_finite.hpp"
#include "io/number_parse.hpp"
#include "io/record_convert.hpp"
#include "io/scalar_type.hpp"
#include "io/text_chunks.hpp"
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

    // Most bytes one item can take in a binary body (every list at the
    // longest length its count type can state); saturates at UINT64_MAX.
    [[nodiscard]] uint64_t maxBinaryItemSize() const {
        uint64_t size = 0;
        for (const PlyProperty& p : properties) {
            uint64_t item = scalarSize(p.type);
            if (p.isList) {
                const size_t countBits = 8 * scalarSize(p.countType);
                if (countBits >= 64) return UINT64_MAX;
                item = scalarSize(p.countType) + ((uint64_t{1} << countBits) - 1) * scalarSize(p.type);
            }
            if (item > UINT64_MAX - size) return UINT64_MAX;
            size += item;
        }
        return size;
    }
};

// Bytes per item of an element without list properties; 0 when it has one
// (or no property at all).
uint64_t fixedItemSize(const PlyElement& e) {
    uint64_t size = 0;
    for (const PlyProperty& p : e.properties) {
        if (p.isList) return 0;
        size += scalarSize(p.type);
    }
    return size;
}

struct PlyHeader {
    PlyFormat format = PlyFormat::kAscii;
    std::vector<PlyElement> elements;
    size_t bodyOffset = 0;  // first byte after "end_header\n"
    size_t bodyLine = 0;    // line number of the first body line (ascii)
};

// One header line split into its first tokens (n counts past tok's size).
struct HeaderLine {
    std::array<std::string_view, 6> tok{};
    size_t n = 0;
    size_t lineNo = 0;
};

std::optional<Error> parseFormat(const HeaderLine& l, const std::string& path, PlyFormat& format) {
    if (l.n < 2) return badInput(path, lineWhere(l.lineNo), "format line without a format");
    if (l.tok[1] == "ascii") {
        format = PlyFormat::kAscii;
    } else if (l.tok[1] == "binary_little_endian") {
        format = PlyFormat::kBinaryLittleEndian;
    } else if (l.tok[1] == "binary_big_endian") {
        format = PlyFormat::kBinaryBigEndian;
    } else {
        return badInput(path, lineWhere(l.lineNo), "unsupported format '" + std::string(l.tok[1]) + "'");
    }
    if (l.n >= 3 && l.tok[2] != "1.0" && l.tok[2] != "1") {
        return badInput(path, lineWhere(l.lineNo), "unsupported PLY version '" + std::string(l.tok[2]) + "'");
    }
    return std::nullopt;
}

Result<PlyElement> parseElement(const HeaderLine& l, const std::string& path) {
    uint64_t count = 0;
    if (l.n != 3 || !parseUInt(l.tok[2], count)) {
        return badInput(path, lineWhere(l.lineNo), "malformed element line (want 'element <name> <count>')");
    }
    return PlyElement{std::string(l.tok[1]), count, l.lineNo, {}};
}

// "property <type> <name>" or "property list <count type> <item type> <name>".
Result<PlyProperty> parseProperty(const HeaderLine& l, const std::string& path) {
    const std::string where = lineWhere(l.lineNo);
    if (l.n >= 2 && l.tok[1] == "list") {
        if (l.n != 5) {
            return badInput(path, where,
                            "malformed list property (want 'property list <count type> <item type> <name>')");
        }
        const auto countType = plyScalarType(l.tok[2]);
        const auto itemType = plyScalarType(l.tok[3]);
        if (!countType || !isIntegral(*countType)) {
            return badInput(path, where, "unsupported list count type '" + std::string(l.tok[2]) + "'");
        }
        if (!itemType)
            return badInput(path, where, "unsupported property type '" + std::string(l.tok[3]) + "'");
        return PlyProperty{std::string(l.tok[4]), *itemType, true, *countType};
    }
    if (l.n != 3) return badInput(path, where, "malformed property line");
    const auto type = plyScalarType(l.tok[1]);
    if (!type) return badInput(path, where, "unsupported property type '" + std::string(l.tok[1]) + "'");
    return PlyProperty{std::string(l.tok[2]), *type, false, ScalarType::kUInt8};
}

// A property line into the last element declared; names: the property
// names of that element so far (views into the header's bytes), so that a
// header of n properties takes O(n), not O(n^2) (100,000 took 21 s).
std::optional<Error> addProperty(const HeaderLine& l, const std::string& path, PlyHeader& header,
                                 std::unordered_set<std::string_view>& names) {
    if (header.elements.empty()) return badInput(path, lineWhere(l.lineNo), "property before any element");
    Result<PlyProperty> prop = parseProperty(l, path);
    if (!prop) return prop.error();
    PlyElement& element = header.elements.back();
    if (element.properties.size() == kMaxPlyPropertiesPerElement) {
        return badInput(path, lineWhere(l.lineNo),
                        "element " + element.name + " has more than " +
                            std::to_string(kMaxPlyPropertiesPerElement) +
                            " properties (limit of this loader)");
    }
    if (!names.insert(l.tok[l.n - 1]).second) {  // the name ends the line (parseProperty)
        return badInput(path, lineWhere(l.lineNo),
                        "property '" + prop->name + "' declared twice in element " + element.name);
    }
    element.properties.push_back(std::move(*prop));
    return std::nullopt;
}

Result<PlyHeader> parseHeader(std::string_view bytes, const std::string& path) {
    PlyHeader header;
    TextCursor cursor(bytes);
    std::string_view line;
    if (!cursor.nextLine(line) || trimBlank(line) != "ply") {
        return badInput(path, lineWhere(1), "not a PLY file (first line is not 'ply')");
    }
    bool haveFormat = false;
    std::unordered_map<std::string_view, size_t> elementLines;  // each element's name and line
    std::unordered_set<std::string_view> propertyNames;         // of the last element declared
    for (;;) {
        if (!cursor.nextLine(line)) return badInput(path, "header", "no 'end_header' line");
        HeaderLine l;
        l.lineNo = cursor.line();
        l.n = splitTokens(line, l.tok.data(), l.tok.size());
        if (l.n == 0) continue;
        const std::string_view key = l.tok[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            header.bodyOffset = cursor.offset();
            header.bodyLine = l.lineNo + 1;
            break;
        }
        std::optional<Error> error;
        if (key == "format") {
            error = parseFormat(l, path, header.format);
            haveFormat = true;
        } else if (key == "element") {
            Result<PlyElement> element = parseElement(l, path);
            if (!element) return element.error();
            // A second "vertex" was skipped, its points never read: every name once.
            if (const auto [at, added] = elementLines.emplace(l.tok[1], l.lineNo); !added) {
                return badInput(path, lineWhere(l.lineNo),
                                "element '" + element->name + "' declared twice (first on line " +
                                    std::to_string(at->second) + ")");
            }
            header.elements.push_back(std::move(*element));
            std::unordered_set<std::string_view>().swap(propertyNames);  // clear() is O(buckets)
        } else if (key == "property") {
            error = addProperty(l, path, header, propertyNames);
        } else {
            return badInput(path, lineWhere(l.lineNo), "unknown header keyword '" + std::string(key) + "'");
        }
        if (error) return *error;
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

    // Rejects elements[first, last) whose fixed-size parts alone (lists
    // counted empty) need more bytes than remain: before any allocation, and
    // so that a vertex count that is too high cannot take the bytes of the
    // elements after it.
    std::optional<Error> checkFit(const std::vector<PlyElement>& elements, size_t first, size_t last) const {
        const uint64_t left = m_bytes.size() - m_pos;
        uint64_t need = 0;
        for (size_t ei = first; ei < last; ++ei) {
            const PlyElement& e = elements[ei];
            const uint64_t minSize = e.minBinaryItemSize();
            if (minSize == 0) continue;
            if (e.count > (left - need) / minSize) {
                return badInput(m_path, offsetWhere(m_pos),
                                "element " + e.name + " declares " + std::to_string(e.count) +
                                    " items of at least " + std::to_string(minSize) + " bytes, but only " +
                                    std::to_string(left - need) + " of the " + std::to_string(left) +
                                    " remaining bytes are left for it (truncated body or wrong count)");
            }
            need += e.count * minSize;
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
            if (auto err = skipProperty(e, index, p)) return err;  // a list: its count, then its items
        }
        return std::nullopt;
    }

    std::optional<Error> skipElement(const PlyElement& e) {
        if (e.properties.empty()) return std::nullopt;
        const uint64_t size = fixedItemSize(e);
        if (size != 0 && e.count <= (m_bytes.size() - m_pos) / size) {
            m_pos += static_cast<size_t>(e.count * size);  // every item fits: nothing to check inside
            return std::nullopt;
        }
        for (uint64_t k = 0; k < e.count; ++k) {
            if (auto err = item(e, k, nullptr, nullptr)) return err;
        }
        return std::nullopt;
    }

    // Walks one item of the face element, the list property `listProp`'s
    // values into polygon (each an integer >= 0, else the error naming the
    // face).
    std::optional<Error> faceItem(const PlyElement& e, uint64_t index, size_t listProp,
                                  std::vector<int64_t>& polygon) {
        polygon.clear();
        const size_t start = m_pos;
        for (size_t i = 0; i < e.properties.size(); ++i) {
            const PlyProperty& p = e.properties[i];
            if (i != listProp) {
                if (auto err = skipProperty(e, index, p)) return err;
                continue;
            }
            const size_t countSize = scalarSize(p.countType);
            if (m_bytes.size() - m_pos < countSize) return truncated(e, index);
            const double count = loadScalar(m_bytes.data() + m_pos, p.countType, m_bigEndian);
            const size_t itemSize = scalarSize(p.type);
            if (count < 0 || count > static_cast<double>((m_bytes.size() - m_pos - countSize) / itemSize)) {
                return count < 0 ? badInput(m_path, offsetWhere(m_pos),
                                            "face " + std::to_string(index) + ": negative list length")
                                 : truncated(e, index);
            }
            m_pos += countSize;
            for (size_t k = 0; k < static_cast<size_t>(count); ++k, m_pos += itemSize) {
                const double v = loadScalar(m_bytes.data() + m_pos, p.type, m_bigEndian);
                if (!(v >= 0) || v != std::floor(v) || v > 9.0e18) {
                    return badInput(m_path, offsetWhere(start),
                                    "face " + std::to_string(index) + ": vertex index " + std::to_string(v) +
                                        " is not an index");
                }
                polygon.push_back(static_cast<int64_t>(v));
            }
        }
        return std::nullopt;
    }

    [[nodiscard]] size_t position() const { return m_pos; }
    [[nodiscard]] const std::string& path() const { return m_path; }

    // Steps over bytes the caller has read (and checked to be there).
    void advance(uint64_t bytes) { m_pos += static_cast<size_t>(bytes); }
    [[nodiscard]] const char* here() const { return m_bytes.data() + m_pos; }

    // After the last element only padding (blanks, NUL bytes) may follow;
    // anything else means a count or a list length did not match the data.
    std::optional<Error> checkEnd() const {
        for (size_t i = m_pos; i < m_bytes.size(); ++i) {
            if (m_bytes[i] != '\0' && !isBlank(m_bytes[i])) {
                return badInput(m_path, offsetWhere(m_pos),
                                std::to_string(m_bytes.size() - m_pos) +
                                    " bytes follow the last declared element (wrong count or list length)");
            }
        }
        return std::nullopt;
    }

private:
    std::optional<Error> skipProperty(const PlyElement& e, uint64_t index, const PlyProperty& p) {
        if (!p.isList) {
            if (m_bytes.size() - m_pos < scalarSize(p.type)) return truncated(e, index);
            m_pos += scalarSize(p.type);
            return std::nullopt;
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
        // Compared as double first: a uint64 length may not fit size_t arithmetic.
        if (count > static_cast<double>((m_bytes.size() - m_pos) / scalarSize(p.type)))
            return truncated(e, index);
        m_pos += static_cast<size_t>(count) * scalarSize(p.type);
        return std::nullopt;
    }

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

// x, y or z stored as double or as a 32/64-bit integer: the points are kept
// in double; otherwise (float, 8/16-bit integers) float holds them exactly.
Scalar binaryPrecision(const PlyElement& vertex, const XyzIndex& xyz) {
    for (size_t axis = 0; axis < 3; ++axis) {
        if (needsDouble(vertex.properties[xyz.prop[axis]].type)) return Scalar::kFloat64;
    }
    return Scalar::kFloat32;
}

// The vertex element as fixed-size records, when it has no list property.
std::optional<RecordLayout> fixedLayout(const PlyElement& vertex, const XyzIndex& xyz, const char* first,
                                        bool bigEndian) {
    const uint64_t stride = fixedItemSize(vertex);
    if (stride == 0) return std::nullopt;
    RecordLayout layout{first, static_cast<size_t>(stride), vertex.count, {}, {}, bigEndian};
    for (size_t axis = 0; axis < 3; ++axis) {
        size_t offset = 0;
        for (size_t i = 0; i < xyz.prop[axis]; ++i) offset += scalarSize(vertex.properties[i].type);
        layout.offset[axis] = offset;
        layout.type[axis] = vertex.properties[xyz.prop[axis]].type;
    }
    return layout;
}

// Reads the vertex element into points (sized already, not yet written):
// fixed-size records in parallel chunks, each checked as it is written,
// vertices with list properties item by item. Returns the error of the
// body's structure; nonFinite receives the first vertex with a NaN or
// infinite coordinate, which the caller reports only once the rest of the
// body has been walked (a structural error comes first, as ever).
std::optional<Error> readVertices(BinaryBody& body, const PlyElement& vertex, const XyzIndex& xyz,
                                  bool bigEndian, const ChunkPlan& plan, PointCloud& points,
                                  std::optional<Error>& nonFinite) {
    const bool doubles = points.scalar == Scalar::kFloat64;
    const std::string& path = body.path();
    if (auto layout = fixedLayout(vertex, xyz, body.here(), bigEndian)) {
        // checkFit has made sure that every record is in the file.
        nonFinite = doubles ? convertRecords(*layout, points.doubles.data(), plan, path)
                            : convertRecords(*layout, points.floats.data(), plan, path);
        body.advance(vertex.count * layout->stride);
        return std::nullopt;
    }
    double v[3] = {0, 0, 0};
    for (uint64_t k = 0; k < vertex.count; ++k) {
        if (auto err = body.item(vertex, k, &xyz, v)) return err;
        if (doubles) {
            points.doubles[k] = glm::dvec3(v[0], v[1], v[2]);
        } else {
            points.floats[k] = glm::vec3(narrowToFloat(v[0]), narrowToFloat(v[1]), narrowToFloat(v[2]));
        }
    }
    nonFinite = checkFiniteCloud(points, path, plan);
    return std::nullopt;
}

Result<PointCloud> readBinaryBody(std::string_view bytes, const PlyHeader& header, size_t vertexElement,
                                  const XyzIndex& xyz, const std::string& path, const ChunkPlan& plan) {
    const bool bigEndian = header.format == PlyFormat::kBinaryBigEndian;
    BinaryBody body(bytes, header.bodyOffset, bigEndian, path);
    for (size_t ei = 0; ei < vertexElement; ++ei) {
        if (auto err = body.checkFit(header.elements, ei, ei + 1)) return *err;
        if (auto err = body.skipElement(header.elements[ei])) return *err;
    }
    if (auto err = body.checkFit(header.elements, vertexElement, header.elements.size())) return *err;
    const PlyElement& vertex = header.elements[vertexElement];
    PointCloud points;
    points.scalar = binaryPrecision(vertex, xyz);
    if (points.scalar == Scalar::kFloat64) {  // unwritten: readVertices writes each vertex
        points.doubles.resize(static_cast<size_t>(vertex.count));
    } else {
        points.floats.resize(static_cast<size_t>(vertex.count));
    }
    std::optional<Error> nonFinite;
    if (auto err = readVertices(body, vertex, xyz, bigEndian, plan, points, nonFinite)) return *err;
    for (size_t ei = vertexElement + 1; ei < header.elements.size(); ++ei) {
        if (auto err = body.skipElement(header.elements[ei])) return *err;
    }
    if (auto err = body.checkEnd()) return *err;
    if (nonFinite) return *nonFinite;
    return points;
}

// ---- ascii bodies ----------------------------------------------------------

// An ascii body holds one item per line (Turk: "each element on its own
// line"), so a wrong count or a stray value cannot shift later items: the
// n-th non-blank body line is item n over the elements in header order,
// which lets chunks of lines be parsed in parallel.
bool isItemLine(std::string_view line) { return !trimBlank(line).empty(); }

// Every declared item with properties needs its own non-blank line: checked
// for all elements (also those after the vertex element) before anything
// is allocated.
std::optional<Error> checkAsciiFit(const std::vector<PlyElement>& elements, uint64_t lines,
                                   const std::string& path) {
    uint64_t need = 0;
    for (const PlyElement& e : elements) {
        if (e.properties.empty()) continue;
        if (e.count > lines - need) {
            return badInput(path, "element " + e.name,
                            "declares " + std::to_string(e.count) + " items (one per line), but only " +
                                std::to_string(lines - need) + " of the " + std::to_string(lines) +
                                " non-blank body lines are left for it (truncated body or wrong count)");
        }
        need += e.count;
    }
    return std::nullopt;
}

// Checks item `index` of e on its line (number lineNo); for the vertex
// element, values[axis] receives x/y/z.
std::optional<Error> parseAsciiItem(std::string_view line, size_t lineNo, const PlyElement& e, uint64_t index,
                                    const XyzIndex* xyz, double* values, const std::string& path) {
    TextCursor tokens(line, lineNo);
    auto itemWhere = [&] { return "element " + e.name + " item " + std::to_string(index); };
    size_t found = 0;
    auto next = [&](std::string_view& tok) -> std::optional<Error> {
        tok = tokens.nextToken();
        if (tok.empty()) {
            return badInput(path, lineWhere(lineNo),
                            itemWhere() + ": the line ends after " + std::to_string(found) +
                                " values, the properties need more (one item per line)");
        }
        ++found;
        return std::nullopt;
    };
    for (size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& p = e.properties[i];
        std::string_view tok;
        if (auto err = next(tok)) return err;
        if (p.isList) {
            uint64_t length = 0;
            if (!parseUInt(tok, length)) {
                return badInput(path, lineWhere(lineNo),
                                itemWhere() + ": bad list length '" + std::string(tok) + "'");
            }
            for (uint64_t t = 0; t < length; ++t) {
                if (auto err = next(tok)) return err;
            }
            continue;
        }
        if (xyz == nullptr) continue;
        for (size_t axis = 0; axis < 3; ++axis) {
            if (xyz->prop[axis] != i) continue;
            if (!parseDouble(tok, values[axis])) {
                return badInput(
                    path, lineWhere(lineNo),
                    "vertex " + std::to_string(index) + " property " + p.name + ": " + notANumber(tok));
            }
        }
    }
    if (!tokens.nextToken().empty()) {
        return badInput(path, lineWhere(lineNo),
                        itemWhere() + ": more values than its " + std::to_string(found) +
                            " declared ones (one item per line)");
    }
    return std::nullopt;
}

// The first item of each element that has properties, in body order.
struct ItemRange {
    uint64_t first = 0;
    size_t element = 0;
};

std::vector<ItemRange> itemRanges(const std::vector<PlyElement>& elements, uint64_t& need) {
    std::vector<ItemRange> ranges;
    need = 0;
    for (size_t ei = 0; ei < elements.size(); ++ei) {
        if (elements[ei].properties.empty() || elements[ei].count == 0) continue;
        ranges.push_back(ItemRange{need, ei});
        need += elements[ei].count;
    }
    return ranges;
}

Result<PointCloud> readAsciiBody(std::string_view bytes, const PlyHeader& header, size_t vertexElement,
                                 const XyzIndex& xyz, const std::string& path, const ChunkPlan& plan) {
    const std::string_view text = bytes.substr(header.bodyOffset);
    const TextChunks chunks = splitLines(text, header.bodyLine, &isItemLine, plan);
    if (auto err = checkAsciiFit(header.elements, chunks.items, path)) return *err;
    uint64_t need = 0;
    const std::vector<ItemRange> ranges = itemRanges(header.elements, need);
    PointArray<glm::dvec3> points(static_cast<size_t>(header.elements[vertexElement].count), glm::dvec3(0.0));
    auto err = parseChunks(
        chunks, text, plan, [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
            uint64_t g = chunk.firstItem;
            size_t r = 0;
            std::string_view line;
            while (cursor.nextLine(line)) {
                if (!isItemLine(line)) continue;
                if (g >= need) {
                    return badInput(path, lineWhere(cursor.line()),
                                    "text after the last declared element (wrong count)");
                }
                while (r + 1 < ranges.size() && ranges[r + 1].first <= g) ++r;
                const bool isVertex = ranges[r].element == vertexElement;
                const uint64_t k = g - ranges[r].first;
                double v[3] = {0, 0, 0};
                if (auto e = parseAsciiItem(line, cursor.line(), header.elements[ranges[r].element], k,
                                            isVertex ? &xyz : nullptr, v, path)) {
                    return e;
                }
                if (isVertex) points[k] = glm::dvec3(v[0], v[1], v[2]);
                ++g;
            }
            return std::nullopt;
        });
    if (err) return *err;
    if (auto bad = firstNonFinite(points.data(), points.size(), path, plan)) return *bad;
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

// The face element and its index list: "face" with "vertex_indices" (or
// "vertex_index", older files).
struct FaceIndex {
    size_t element = 0;
    size_t list = 0;
};

Result<FaceIndex> findFaces(const PlyHeader& header, const std::string& path) {
    for (size_t ei = 0; ei < header.elements.size(); ++ei) {
        const PlyElement& e = header.elements[ei];
        if (e.name != "face") continue;
        for (size_t i = 0; i < e.properties.size(); ++i) {
            const PlyProperty& p = e.properties[i];
            if ((p.name == "vertex_indices" || p.name == "vertex_index") && p.isList) return FaceIndex{ei, i};
        }
        return badInput(path, "element face", "no list property 'vertex_indices' (or 'vertex_index')");
    }
    return badInput(path, "header", "no 'face' element: the file has no triangles");
}

Result<std::vector<uint32_t>> readBinaryFaces(std::string_view bytes, const PlyHeader& header,
                                              const FaceIndex& faceIndex, uint64_t vertexCount,
                                              const std::string& path) {
    BinaryBody body(bytes, header.bodyOffset, header.format == PlyFormat::kBinaryBigEndian, path);
    for (size_t ei = 0; ei < faceIndex.element; ++ei) {
        if (auto err = body.checkFit(header.elements, ei, ei + 1)) return *err;
        if (auto err = body.skipElement(header.elements[ei])) return *err;
    }
    const PlyElement& face = header.elements[faceIndex.element];
    if (auto err = body.checkFit(header.elements, faceIndex.element, faceIndex.element + 1)) return *err;
    FaceList faces(vertexCount);
    std::vector<int64_t> polygon;
    for (uint64_t f = 0; f < face.count; ++f) {
        const size_t at = body.position();
        if (auto err = body.faceItem(face, f, faceIndex.list, polygon)) return *err;
        if (auto err = faces.addPolygon(path, offsetWhere(at), f, polygon)) return *err;
    }
    return faces.take();
}

// The face element's lines (one item per non-blank line, after the items of
// the elements before it), in one serial pass.
Result<std::vector<uint32_t>> readAsciiFaces(std::string_view bytes, const PlyHeader& header,
                                             const FaceIndex& faceIndex, uint64_t vertexCount,
                                             const std::string& path) {
    uint64_t skip = 0;
    for (size_t ei = 0; ei < faceIndex.element; ++ei) {
        if (!header.elements[ei].properties.empty()) skip += header.elements[ei].count;
    }
    const PlyElement& face = header.elements[faceIndex.element];
    TextCursor cursor(bytes.substr(header.bodyOffset), header.bodyLine);
    FaceList faces(vertexCount);
    std::vector<int64_t> polygon;
    std::string_view line;
    uint64_t item = 0;
    uint64_t f = 0;
    while (f < face.count && cursor.nextLine(line)) {
        if (!isItemLine(line)) continue;
        if (item++ < skip) continue;
        TextCursor tokens(line, cursor.line());
        polygon.clear();
        for (size_t i = 0; i < face.properties.size(); ++i) {
            const std::string_view tok = tokens.nextToken();
            uint64_t length = 0;
            if (!face.properties[i].isList) continue;
            if (!parseUInt(tok, length)) {
                return badInput(path, lineWhere(cursor.line()),
                                "face " + std::to_string(f) + ": bad list length '" + std::string(tok) + "'");
            }
            for (uint64_t k = 0; k < length; ++k) {
                const std::string_view v = tokens.nextToken();
                if (i != faceIndex.list) continue;
                uint64_t index = 0;
                if (!parseUInt(v, index) || index > uint64_t(INT64_MAX)) {
                    return badInput(
                        path, lineWhere(cursor.line()),
                        "face " + std::to_string(f) + ": '" + std::string(v) + "' is not a vertex index");
                }
                polygon.push_back(int64_t(index));
            }
        }
        if (auto err = faces.addPolygon(path, lineWhere(cursor.line()), f, polygon)) return *err;
        ++f;
    }
    return faces.take();
}

}  // namespace

Result<std::vector<uint32_t>> readPlyFaces(std::string_view bytes, const std::string& path,
                                           uint64_t vertexCount) {
    auto header = parseHeader(bytes, path);
    if (!header) return header.error();
    auto faceIndex = findFaces(*header, path);
    if (!faceIndex) return faceIndex.error();
    if (header->format == PlyFormat::kAscii)
        return readAsciiFaces(bytes, *header, *faceIndex, vertexCount, path);
    return readBinaryFaces(bytes, *header, *faceIndex, vertexCount, path);
}

Result<PointCloud> readPly(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
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
    if (header->format == PlyFormat::kAscii) {
        return readAsciiBody(bytes, *header, vertexElement, *xyz, path, plan);
    }
    return readBinaryBody(bytes, *header, vertexElement, *xyz, path, plan);
}

Result<uint64_t> plyInflatedBound(std::string_view head, bool whole, const std::string& path) {
    // A header longer than the head: nothing to say yet (the reader decides).
    if (!whole && head.find("end_header") == std::string_view::npos) return kNoInflatedBound;
    auto header = parseHeader(head, path);
    if (!header) return header.error();
    if (header->format == PlyFormat::kAscii) return kNoInflatedBound;  // numbers have no longest spelling
    uint64_t size = header->bodyOffset;
    for (const PlyElement& e : header->elements) {
        const uint64_t itemSize = e.maxBinaryItemSize();
        if (itemSize != 0 && e.count > (UINT64_MAX - size) / itemSize) return kNoInflatedBound;
        size += e.count * itemSize;
    }
    return size;
}

}  // namespace rthdist::io
