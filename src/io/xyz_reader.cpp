#include "io/xyz_reader.hpp"

#include <array>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/text_chunks.hpp"

namespace rthdist::io {
namespace {

bool isPointLine(std::string_view line) {
    const std::string_view body = trimBlank(line);
    return !body.empty() && body.front() != '#' && !body.starts_with("//");
}

// The shortest point line, "0 0 0" and its line end: more point lines than
// this allows means one of them is not a point.
constexpr size_t kShortestPointLine = 6;

}  // namespace

Result<PointCloud> readXyz(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    const std::string_view text = bytes.substr(bomLength(bytes));
    auto pointOf = [&](std::string_view line, const TextCursor& cursor,
                       glm::dvec3& p) -> std::optional<Error> {
        std::array<std::string_view, 3> tok{};
        const size_t n = splitTokens(trimBlank(line), tok.data(), tok.size(), ",;");
        if (n < 3)
            return badInput(path, lineWhere(cursor.line()),
                            "expected 'x y z', found " + std::to_string(n) + " column(s)");
        if (const auto bad = parsePoint(tok.data(), p))
            return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
        return std::nullopt;
    };
    Result<std::vector<glm::dvec3>> points =
        readPointLines(text, plan, &isPointLine, kShortestPointLine, pointOf);
    if (!points) return points.error();
    return PointCloud{Scalar::kFloat64, {}, std::move(points.value())};
}

}  // namespace rthdist::io
