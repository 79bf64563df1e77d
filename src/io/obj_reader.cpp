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
    auto pointOf = [&](std::string_view line, const TextCursor& cursor,
                       glm::dvec3& p) -> std::optional<Error> {
        std::array<std::string_view, 4> tok{};
        const size_t n = splitTokens(trimBlank(line).substr(1), tok.data(), tok.size());
        if (n < 3)
            return badInput(path, lineWhere(cursor.line()),
                            "vertex line with " + std::to_string(n) + " coordinate(s)");
        if (const auto bad = parsePoint(tok.data(), p))
            return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
        return std::nullopt;
    };
    Result<std::vector<glm::dvec3>> points =
        readPointLines(text, plan, &isVertexLine, kShortestVertexLine, pointOf);
    if (!points) return points.error();
    return PointCloud{Scalar::kFloat64, {}, std::move(points.value())};
}

}  // namespace rthdist::io
