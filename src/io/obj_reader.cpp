#include "io/obj_reader.hpp"

#include <array>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/text_chunks.hpp"

namespace rthdist::io {
namespace {

// Only geometric vertices: "v " and "v\t" (not vn, vt, vp).
bool isVertexLine(std::string_view line) {
    const std::string_view body = trimBlank(line);
    return body.size() >= 2 && body[0] == 'v' && (body[1] == ' ' || body[1] == '\t');
}

// The shortest vertex line, "v 0 0 0" and its line end.
constexpr size_t kShortestVertexLine = 8;

}  // namespace

Result<PointCloud> readObj(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    const std::string_view text = bytes.substr(bomLength(bytes));
    const TextChunks chunks = splitLines(text, 1, &isVertexLine, plan);
    std::vector<glm::dvec3> points;
    auto parse = [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
        uint64_t k = chunk.firstItem;
        std::string_view line;
        while (cursor.nextLine(line)) {
            if (!isVertexLine(line)) continue;
            std::array<std::string_view, 4> tok{};
            const size_t n = splitTokens(trimBlank(line).substr(1), tok.data(), tok.size());
            if (n < 3) {
                return badInput(path, lineWhere(cursor.line()),
                                "vertex line with " + std::to_string(n) + " coordinate(s)");
            }
            glm::dvec3 p;
            if (const auto bad = parsePoint(tok.data(), p)) {
                return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
            }
            if (!points.empty()) points[k] = p;
            ++k;
        }
        return std::nullopt;
    };
    // Too many vertex lines for the file's size: find the bad one before
    // allocating for all of them.
    if (chunks.items > (text.size() + 1) / kShortestVertexLine) {
        if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    }
    points.resize(static_cast<size_t>(chunks.items));
    if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

}  // namespace rthdist::io
