#include "io/xyz_reader.hpp"

#include <array>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {

Result<PointCloud> readXyz(std::string_view bytes, const std::string& path) {
    std::vector<glm::dvec3> points;
    // Shortest point line: "0 0 0\n".
    points.reserve(bytes.size() / 6 + 1);
    TextCursor cursor(bytes);
    std::string_view line;
    while (cursor.nextLine(line)) {
        const std::string_view body = trimBlank(line);
        if (body.empty() || body.front() == '#' || body.starts_with("//")) continue;
        std::array<std::string_view, 3> tok{};
        const size_t n = splitTokens(body, tok.data(), tok.size(), ",;");
        if (n < 3) {
            return badInput(path, lineWhere(cursor.line()),
                            "expected 'x y z', found " + std::to_string(n) + " column(s)");
        }
        glm::dvec3 p;
        if (const auto bad = parsePoint(tok.data(), p)) {
            return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
        }
        points.push_back(p);
    }
    points.shrink_to_fit();
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

}  // namespace rthdist::io
