// PCD v0.7 as documented by the Point Cloud Library ("The PCD (Point Cloud
// Data) file format"): a text header, then ascii rows, packed binary rows,
// or (binary_compressed, PCL's pcl::io::savePCDFileBinaryCompressed) two
// little-endian uint32 sizes, compressed and uncompressed, and the LZF
// stream of every field's values one field after another (all points' x,
// then all points' y, ...), inflated by Debian's liblzf.
#include "io/pcd_reader.hpp"

#include <lzf.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <optional>

#include "io/io_error.hpp"
#include "io/non_finite.hpp"
#include "io/number_parse.hpp"
#include "io/record_convert.hpp"
#include "io/scalar_type.hpp"
#include "io/text_chunks.hpp"

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

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdHeader {
    std::vector<PcdField> fields;
    uint64_t points = 0;
    PcdData data = PcdData::kAscii;
    size_t dataLine = 0;
    size_t bodyOffset = 0;  // first byte after the DATA line
};

// Header state while its lines are read.
struct HeaderState {
    std::vector<PcdField> fields;
    std::optional<uint64_t> points;
    uint64_t width = 0;
    uint64_t height = 1;
    std::string data;
    size_t dataLine = 0;
};

// Applies one header line (key tok[0], n tokens) to the state.
std::optional<Error> applyHeaderLine(HeaderState& h, const std::string_view* tok, size_t n, size_t lineNo,
                                     const std::string& path) {
    const std::string_view key = tok[0];
    auto where = lineWhere(lineNo);
    auto perField = [&](const char* what) -> std::optional<Error> {
        if (n - 1 != h.fields.size()) {
            return badInput(path, where,
                            std::string(what) + " has " + std::to_string(n - 1) + " values for " +
                                std::to_string(h.fields.size()) + " fields");
        }
        return std::nullopt;
    };
    if (key == "VERSION" || key == "VIEWPOINT") return std::nullopt;
    if (key == "FIELDS" || key == "COLUMNS") {
        h.fields.clear();
        for (size_t i = 1; i < n; ++i) h.fields.push_back(PcdField{std::string(tok[i])});
    } else if (key == "SIZE") {
        if (auto err = perField("SIZE")) return err;
        for (size_t i = 1; i < n; ++i) {
            uint64_t s = 0;
            if (!parseUInt(tok[i], s) || s == 0 || s > 8)
                return badInput(path, where, "bad SIZE '" + std::string(tok[i]) + "'");
            h.fields[i - 1].size = static_cast<size_t>(s);
        }
    } else if (key == "TYPE") {
        if (auto err = perField("TYPE")) return err;
        for (size_t i = 1; i < n; ++i) {
            if (tok[i].size() != 1) return badInput(path, where, "bad TYPE '" + std::string(tok[i]) + "'");
            h.fields[i - 1].type = tok[i][0];
        }
    } else if (key == "COUNT") {
        if (auto err = perField("COUNT")) return err;
        for (size_t i = 1; i < n; ++i) {
            uint64_t c = 0;
            if (!parseUInt(tok[i], c) || c == 0 || c > 1'000'000) {
                return badInput(path, where, "bad COUNT '" + std::string(tok[i]) + "'");
            }
            h.fields[i - 1].count = c;
        }
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
        uint64_t v = 0;
        if (n != 2 || !parseUInt(tok[1], v))
            return badInput(path, where, "bad " + std::string(key) + " line");
        if (key == "WIDTH") h.width = v;
        if (key == "HEIGHT") h.height = v;
        if (key == "POINTS") h.points = v;
    } else if (key == "DATA") {
        if (n != 2) return badInput(path, where, "bad DATA line");
        h.data = std::string(tok[1]);
        h.dataLine = lineNo;
    } else {
        return badInput(path, where, "unknown header keyword '" + std::string(key) + "'");
    }
    return std::nullopt;
}

Result<PcdHeader> parseHeader(std::string_view bytes, const std::string& path) {
    TextCursor cursor(bytes);
    HeaderState h;
    std::string_view line;
    // Headers have a handful of fields in practice; 4096 bounds the work
    // (refilled per line, only the first n are read).
    std::array<std::string_view, 4096> tok{};
    while (h.data.empty()) {
        if (!cursor.nextLine(line)) return badInput(path, "header", "no DATA line");
        const std::string_view body = trimBlank(line);
        if (body.empty() || body.front() == '#') continue;
        const size_t n = splitTokens(body, tok.data(), tok.size());
        if (n > tok.size()) return badInput(path, lineWhere(cursor.line()), "too many header values");
        if (auto err = applyHeaderLine(h, tok.data(), n, cursor.line(), path)) return *err;
    }
    if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed") {
        return badInput(path, lineWhere(h.dataLine),
                        "unsupported DATA '" + h.data + "' (ascii, binary or binary_compressed only)");
    }
    if (h.height != 0 && h.width > UINT64_MAX / h.height)
        return badInput(path, "header", "WIDTH * HEIGHT overflows");
    if (!h.points) {
        h.points = h.width * h.height;
    } else if (h.width != 0 && h.width * h.height != *h.points) {
        // PCL refuses such a header too: which count holds is not known.
        return badInput(path, "header",
                        "WIDTH * HEIGHT is " + std::to_string(h.width * h.height) + " but POINTS is " +
                            std::to_string(*h.points));
    }
    const PcdData data = h.data == "ascii"    ? PcdData::kAscii
                         : h.data == "binary" ? PcdData::kBinary
                                              : PcdData::kBinaryCompressed;
    return PcdHeader{std::move(h.fields), *h.points, data, h.dataLine, cursor.offset()};
}

// Where x, y, z are in a row (the first element of each), and its size.
struct PcdLayout {
    std::array<uint64_t, 3> column{};      // ascii value index
    std::array<uint64_t, 3> byteOffset{};  // binary byte offset
    std::array<ScalarType, 3> scalar{};
    std::array<uint64_t, 3> fieldBytes{};  // of the axis's field in a row (COUNT x SIZE)
    uint64_t valuesPerRow = 0;
    uint64_t bytesPerRow = 0;
};

Result<PcdLayout> layoutOf(const std::vector<PcdField>& fields, const std::string& path) {
    PcdLayout l;
    std::array<bool, 3> found{};
    constexpr std::array<std::string_view, 3> kNames = {"x", "y", "z"};
    for (const PcdField& f : fields) {
        const auto type = pcdScalarType(f.type, f.size);
        if (!type) {
            return badInput(
                path, "field " + f.name,
                "unsupported TYPE " + std::string(1, f.type) + " with SIZE " + std::to_string(f.size));
        }
        for (size_t axis = 0; axis < 3; ++axis) {
            if (f.name == kNames[axis] && !found[axis]) {
                found[axis] = true;
                l.column[axis] = l.valuesPerRow;
                l.byteOffset[axis] = l.bytesPerRow;
                l.scalar[axis] = *type;
                l.fieldBytes[axis] = f.count * f.size;
            }
        }
        l.valuesPerRow += f.count;
        l.bytesPerRow += f.count * f.size;
    }
    for (size_t axis = 0; axis < 3; ++axis) {
        if (!found[axis]) return badInput(path, "header", "no field '" + std::string(kNames[axis]) + "'");
    }
    return l;
}

// The cloud of binary records (rows, or the compressed columns): double
// where an axis's type needs it, else float32; each point converted once.
Result<PointCloud> cloudOf(const RecordLayout& rows, const std::string& path, const ChunkPlan& plan) {
    PointCloud out;
    out.scalar =
        std::any_of(rows.type.begin(), rows.type.end(), needsDouble) ? Scalar::kFloat64 : Scalar::kFloat32;
    std::optional<Error> bad;
    if (out.scalar == Scalar::kFloat64) {
        out.doubles.resize(static_cast<size_t>(rows.count));  // unwritten: convertRecords writes each point
        bad = convertRecords(rows, out.doubles.data(), plan, path);
    } else {
        out.floats.resize(static_cast<size_t>(rows.count));
        bad = convertRecords(rows, out.floats.data(), plan, path);
    }
    if (bad) return *bad;
    return out;
}

Result<PointCloud> readBinaryRows(std::string_view bytes, const PcdHeader& h, const PcdLayout& l,
                                  const std::string& path, const ChunkPlan& plan) {
    if (auto e = checkRecordsFit(path, h.bodyOffset, "", h.points, l.bytesPerRow, bytes.size() - h.bodyOffset,
                                 "remain (truncated body or wrong count)"))
        return *e;
    // After the rows only zeros may follow (PCL pads its files to a page): a
    // nonzero byte could be a row the header leaves out.
    const size_t end = h.bodyOffset + size_t(h.points * l.bytesPerRow);
    const size_t stray = bytes.find_first_not_of('\0', end);
    if (stray != std::string_view::npos) {
        return badInput(path, offsetWhere(end),
                        "the header declares " + std::to_string(h.points) + " points of " +
                            std::to_string(l.bytesPerRow) + " bytes, but data follows them (" +
                            std::to_string(bytes.size() - end) + " bytes past the last row)");
    }
    const RecordLayout rows{bytes.data() + h.bodyOffset,
                            static_cast<size_t>(l.bytesPerRow),
                            h.points,
                            {l.byteOffset[0], l.byteOffset[1], l.byteOffset[2]},
                            l.scalar,
                            false};
    return cloudOf(rows, path, plan);
}

// binary_compressed: an LZF stream inflates at most 88 times (a 3-byte
// back reference copies up to 264 bytes); a declared size past that is
// refused before anything is allocated.
constexpr uint64_t kMaxLzfRatio = 88;

uint32_t readLe32(const char* p) {
    uint32_t v = 0;
    for (int k = 3; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(p[k]);
    return v;
}

// The inflated fields hold each axis's values as a column (stride: its
// field's bytes); columns of one stride convert in place, others are
// gathered into xyz records first.
Result<PointCloud> readCompressedColumns(std::string_view bytes, const PcdHeader& h, const PcdLayout& l,
                                         const std::string& path, const ChunkPlan& plan) {
    const size_t at = h.bodyOffset;
    if (bytes.size() - at < 8)
        return badInput(path, offsetWhere(at),
                        "binary_compressed: the two 4-byte sizes are missing (truncated)");
    const uint32_t compressed = readLe32(bytes.data() + at), inflated = readLe32(bytes.data() + at + 4);
    if (compressed > bytes.size() - at - 8) {
        return badInput(path, offsetWhere(at),
                        "binary_compressed: declares " + std::to_string(compressed) +
                            " compressed bytes, but only " + std::to_string(bytes.size() - at - 8) +
                            " follow (truncated)");
    }
    if (h.points > UINT32_MAX / l.bytesPerRow || uint64_t(inflated) != h.points * l.bytesPerRow) {
        return badInput(path, offsetWhere(at + 4),
                        "binary_compressed: " + std::to_string(h.points) + " points of " +
                            std::to_string(l.bytesPerRow) + " bytes need " +
                            std::to_string(h.points * l.bytesPerRow) + " bytes, the stream declares " +
                            std::to_string(inflated) + " (at most 4 GiB - 1)");
    }
    if (uint64_t(inflated) > kMaxLzfRatio * compressed) {
        return badInput(path, offsetWhere(at),
                        "binary_compressed: " + std::to_string(compressed) + " LZF bytes cannot inflate to " +
                            std::to_string(inflated) + " (at most " + std::to_string(kMaxLzfRatio) +
                            " times)");
    }
    std::vector<char> columns(inflated);
    const unsigned got = lzf_decompress(bytes.data() + at + 8, compressed, columns.data(), inflated);
    if (got != inflated) {
        return badInput(path, offsetWhere(at + 8),
                        "binary_compressed: the LZF stream is corrupt (" +
                            (got == 0 ? std::string("it does not inflate to the declared ") +
                                            std::to_string(inflated) + " bytes"
                                      : "it inflates to " + std::to_string(got) + " of " +
                                            std::to_string(inflated) + " bytes") +
                            ")");
    }
    // Column of each axis: the bytes of the fields before it, for every point.
    std::array<size_t, 3> column{};
    for (size_t axis = 0; axis < 3; ++axis) column[axis] = size_t(l.byteOffset[axis] * h.points);
    RecordLayout rows{columns.data(), size_t(l.fieldBytes[0]), h.points, column, l.scalar, false};
    std::vector<char> gathered;
    if (l.fieldBytes[1] != l.fieldBytes[0] || l.fieldBytes[2] != l.fieldBytes[0]) {
        std::array<size_t, 3> size{}, offset{};
        size_t record = 0;
        for (size_t axis = 0; axis < 3; ++axis) {
            size[axis] = scalarSize(l.scalar[axis]);
            offset[axis] = record;
            record += size[axis];
        }
        gathered.resize(size_t(h.points) * record);
        for (uint64_t i = 0; i < h.points; ++i)
            for (size_t axis = 0; axis < 3; ++axis)
                std::memcpy(&gathered[size_t(i) * record + offset[axis]],
                            &columns[column[axis] + size_t(i * l.fieldBytes[axis])], size[axis]);
        rows = RecordLayout{gathered.data(), record, h.points, offset, l.scalar, false};
    }
    return cloudOf(rows, path, plan);
}

bool isRowLine(std::string_view line) { return !trimBlank(line).empty(); }

// Counts the blank-separated values of line and picks those in columns.
size_t pickColumns(std::string_view line, const std::array<uint64_t, 3>& columns,
                   std::array<std::string_view, 3>& picked) {
    return forEachToken(
        line, [](char c) { return isBlank(c); },
        [&](size_t n, size_t begin, size_t end) {
            for (size_t axis = 0; axis < 3; ++axis) {
                if (columns[axis] == n) picked[axis] = line.substr(begin, end - begin);
            }
        });
}

// One row per non-blank line, parsed in parallel chunks.
Result<PointCloud> readAsciiRows(std::string_view bytes, const PcdHeader& h, const PcdLayout& l,
                                 const std::string& path, const ChunkPlan& plan) {
    const std::string_view text = bytes.substr(h.bodyOffset);
    // Every value is at least one char and a separator.
    if (h.points > (text.size() + 1) / (2 * l.valuesPerRow)) {
        return badInput(path, lineWhere(h.dataLine),
                        "declares " + std::to_string(h.points) + " points but only " +
                            std::to_string(text.size()) + " bytes follow (truncated body or wrong count)");
    }
    TextChunks chunks = splitLines(text, h.dataLine + 1, &isRowLine, plan);
    if (chunks.items > h.points) {
        // Rows the header leaves out would be points silently dropped.
        return badInput(path, lineWhere(h.dataLine),
                        "the header declares " + std::to_string(h.points) + " points but " +
                            std::to_string(chunks.items) + " rows follow");
    }
    keepItems(chunks, text, &isRowLine, h.points);
    PointArray<glm::dvec3> out(static_cast<size_t>(h.points), glm::dvec3(0.0));
    auto err = parseChunks(
        chunks, text, plan, [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
            std::array<std::string_view, 3> tok{};
            uint64_t k = chunk.firstItem;
            std::string_view line;
            while (k < h.points && cursor.nextLine(line)) {
                if (!isRowLine(line)) continue;
                const size_t n = pickColumns(line, l.column, tok);
                if (n < l.valuesPerRow) {
                    return badInput(path, lineWhere(cursor.line()),
                                    "row has " + std::to_string(n) + " values, fields need " +
                                        std::to_string(l.valuesPerRow));
                }
                for (size_t axis = 0; axis < 3; ++axis) {
                    const std::string_view t = tok[axis];
                    if (!parseDouble(t, out[k][static_cast<int>(axis)])) {
                        return badInput(path, lineWhere(cursor.line()), notANumber(t));
                    }
                }
                ++k;
            }
            return std::nullopt;
        });
    if (err) return *err;
    if (chunks.items < h.points) {
        // The line after the file's last one, as a serial walk names it.
        return badInput(
            path, lineWhere(chunks.lastLine() + 1),
            "file ends at point " + std::to_string(chunks.items) + " of " + std::to_string(h.points));
    }
    if (auto bad = firstNonFinite(out.data(), out.size(), path, plan)) return *bad;
    return PointCloud{Scalar::kFloat64, {}, std::move(out)};
}

}  // namespace

Result<PointCloud> readPcd(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    auto header = parseHeader(bytes, path);
    if (!header) return header.error();
    auto layout = layoutOf(header->fields, path);
    if (!layout) return layout.error();
    if (header->points == 0) return PointCloud{};
    if (header->data == PcdData::kBinary) return readBinaryRows(bytes, *header, *layout, path, plan);
    if (header->data == PcdData::kBinaryCompressed)
        return readCompressedColumns(bytes, *header, *layout, path, plan);
    return readAsciiRows(bytes, *header, *layout, path, plan);
}

}  // namespace rthdist::io
