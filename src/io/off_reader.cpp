#include "io/off_reader.hpp"

#include <array>
#include <cstdint>

#include "io/face_list.hpp"
#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/text_chunks.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {
namespace {

// A line without its '#' comment and surrounding blanks.
std::string_view contentOf(std::string_view line) {
    const size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    return trimBlank(line);
}

// Next line that is not blank once its '#' comment is cut off.
bool nextContentLine(TextCursor& cursor, std::string_view& out) {
    std::string_view line;
    while (cursor.nextLine(line)) {
        line = contentOf(line);
        if (!line.empty()) {
            out = line;
            return true;
        }
    }
    return false;
}

bool isContentLine(std::string_view line) { return !contentOf(line).empty(); }

// The vertexCount content lines of text (which starts after the line
// countLine), parsed in parallel chunks.
Result<PointCloud> readVertices(std::string_view text, size_t countLine, uint64_t vertexCount,
                                const std::string& path, const ChunkPlan& plan) {
    TextChunks chunks = splitLines(text, countLine + 1, &isContentLine, plan);
    keepItems(chunks, text, &isContentLine, vertexCount);
    PointArray<glm::dvec3> points(static_cast<size_t>(vertexCount), glm::dvec3(0.0));
    auto err = parseChunks(chunks, text, plan,
                           [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
                               uint64_t k = chunk.firstItem;
                               std::string_view line;
                               while (k < vertexCount && cursor.nextLine(line)) {
                                   line = contentOf(line);
                                   if (line.empty()) continue;
                                   std::array<std::string_view, 3> xyz{};
                                   const size_t m = splitTokens(line, xyz.data(), xyz.size());
                                   if (m < 3) {
                                       return badInput(path, lineWhere(cursor.line()),
                                                       "vertex line with " + std::to_string(m) + " value(s)");
                                   }
                                   if (const auto bad = parsePoint(xyz.data(), points[k])) {
                                       return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
                                   }
                                   ++k;
                               }
                               return std::nullopt;
                           });
    if (err) return *err;
    if (chunks.items < vertexCount) {
        // The file's last line (countLine when none follows), as a serial walk names it.
        return badInput(
            path, lineWhere(chunks.lastLine()),
            "file ends at vertex " + std::to_string(chunks.items) + " of " + std::to_string(vertexCount));
    }
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

}  // namespace

namespace {

// The header: the keyword line and the counts "nv nf ne" (on the same line
// or the next content line).
struct OffHeader {
    uint64_t vertexCount = 0;
    uint64_t faceCount = 0;
    bool hasFaceCount = false;
    size_t countLine = 0;   // the line of the counts
    size_t bodyOffset = 0;  // the first byte after it
};

Result<OffHeader> parseOffHeader(std::string_view bytes, const std::string& path) {
    TextCursor cursor(bytes);
    std::string_view line;
    if (!nextContentLine(cursor, line)) return badInput(path, lineWhere(1), "no OFF header");

    std::array<std::string_view, 5> tok{};
    size_t n = splitTokens(line, tok.data(), tok.size());
    const std::string_view keyword = tok[0];
    // [ST][C][N][4][n]OFF; 4-D and n-D vertices are not 3-D points.
    if (!keyword.ends_with("OFF")) {
        return badInput(path, lineWhere(cursor.line()),
                        "not an OFF file (header '" + std::string(keyword) + "')");
    }
    const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
    if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
        return badInput(path, lineWhere(cursor.line()),
                        "unsupported OFF variant '" + std::string(keyword) + "'");
    }
    if (n >= 2 && tok[1] == "BINARY") {
        return badInput(path, lineWhere(cursor.line()), "binary OFF is not supported");
    }
    // Counts follow on the same line or on the next content line.
    size_t first = 1;
    if (n < 2) {
        if (!nextContentLine(cursor, line))
            return badInput(path, lineWhere(cursor.line()), "no vertex/face counts");
        n = splitTokens(line, tok.data(), tok.size());
        first = 0;
    }
    OffHeader header;
    if (n < first + 1 || !parseUInt(tok[first], header.vertexCount)) {
        return badInput(path, lineWhere(cursor.line()), "bad vertex count (want 'nv nf ne')");
    }
    header.hasFaceCount = n >= first + 2 && parseUInt(tok[first + 1], header.faceCount);
    header.countLine = cursor.line();
    header.bodyOffset = cursor.offset();
    // The shortest vertex line is "0 0 0\n".
    if (header.vertexCount > (cursor.remaining() + 1) / 6) {
        return badInput(path, lineWhere(header.countLine),
                        "declares " + std::to_string(header.vertexCount) + " vertices but only " +
                            std::to_string(cursor.remaining()) +
                            " bytes follow (truncated file or wrong count)");
    }
    return header;
}

// One face line "n i0 .. in-1 [colour]" into polygon.
std::optional<Error> parseFaceLine(std::string_view line, size_t lineNo, uint64_t face,
                                   const std::string& path, std::vector<int64_t>& polygon) {
    TextCursor tokens(line, lineNo);
    const std::string_view countToken = tokens.nextToken();
    uint64_t count = 0;
    if (!parseUInt(countToken, count)) {
        return badInput(
            path, lineWhere(lineNo),
            "face " + std::to_string(face) + ": bad vertex count '" + std::string(countToken) + "'");
    }
    polygon.clear();
    for (uint64_t k = 0; k < count; ++k) {
        const std::string_view token = tokens.nextToken();
        uint64_t v = 0;
        if (token.empty()) {
            return badInput(path, lineWhere(lineNo),
                            "face " + std::to_string(face) + ": the line ends after " + std::to_string(k) +
                                " of its " + std::to_string(count) + " vertex indices");
        }
        if (!parseUInt(token, v) || v > uint64_t(INT64_MAX)) {
            return badInput(
                path, lineWhere(lineNo),
                "face " + std::to_string(face) + ": '" + std::string(token) + "' is not a vertex index");
        }
        polygon.push_back(int64_t(v));
    }
    return std::nullopt;
}

}  // namespace

namespace {

// The body after the vertex block: exactly the header's faces (each parsed
// into `faces`, its indices below the vertex count), then
// nothing but blank lines and comments: a vertex line past the declared
// count, a missing face or a line after the last face is refused (points
// the header leaves out, or a count that does not match the body).
std::optional<Error> walkFaces(std::string_view bytes, const OffHeader& header, const std::string& path,
                               FaceList& faces) {
    TextCursor cursor(bytes.substr(header.bodyOffset), header.countLine + 1);
    std::string_view line;
    for (uint64_t k = 0; k < header.vertexCount; ++k) {
        if (!nextContentLine(cursor, line)) return std::nullopt;  // readVertices refuses a short block
    }
    const uint64_t faceCount = header.hasFaceCount ? header.faceCount : 0;
    std::vector<int64_t> polygon;
    for (uint64_t f = 0; f < faceCount; ++f) {
        if (!nextContentLine(cursor, line)) {
            return badInput(path, lineWhere(cursor.line()),
                            "file ends at face " + std::to_string(f) + " of " + std::to_string(faceCount));
        }
        if (auto err = parseFaceLine(line, cursor.line(), f, path, polygon)) return *err;
        if (auto err = faces.addPolygon(path, lineWhere(cursor.line()), f, polygon)) return *err;
    }
    if (nextContentLine(cursor, line)) {
        return badInput(path, lineWhere(cursor.line()),
                        "a line after the header's " + std::to_string(header.vertexCount) + " vertices and " +
                            std::to_string(faceCount) + " faces (wrong counts?)");
    }
    return std::nullopt;
}

}  // namespace

Result<PointCloud> readOff(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    Result<OffHeader> header = parseOffHeader(bytes, path);
    if (!header) return header.error();
    Result<PointCloud> cloud =
        readVertices(bytes.substr(header->bodyOffset), header->countLine, header->vertexCount, path, plan);
    if (!cloud) return cloud;
    FaceList faces(header->vertexCount);  // checked, then dropped
    if (auto err = walkFaces(bytes, *header, path, faces)) return *err;
    return cloud;
}

Result<std::vector<uint32_t>> readOffFaces(std::string_view bytes, const std::string& path,
                                           uint64_t vertexCount) {
    Result<OffHeader> header = parseOffHeader(bytes, path);
    if (!header) return header.error();
    if (!header->hasFaceCount) {
        return badInput(path, lineWhere(header->countLine), "no face count (want 'nv nf ne')");
    }
    FaceList faces(vertexCount);
    if (auto err = walkFaces(bytes, *header, path, faces)) return *err;
    return faces.take();
}

}  // namespace rthdist::io
