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
    const TextChunks chunks = splitLines(text, 1, &isPointLine, plan);
    std::vector<glm::dvec3> points;
    auto parse = [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
        uint64_t k = chunk.firstItem;
        std::string_view line;
        while (cursor.nextLine(line)) {
            if (!isPointLine(line)) continue;
            std::array<std::string_view, 3> tok{};
            const size_t n = splitTokens(trimBlank(line), tok.data(), tok.size(), ",;");
            if (n < 3) {
                return badInput(path, lineWhere(cursor.line()),
                                "expected 'x y z', found " + std::to_string(n) + " column(s)");
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
    // Too many point lines for the file's size: find the bad one before
    // allocating for all of them.
    if (chunks.items > (text.size() + 1) / kShortestPointLine) {
        if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    }
    points.resize(static_cast<size_t>(chunks.items));
    if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

}  // namespace rthdist::io
