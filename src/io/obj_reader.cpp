#include "io/obj_reader.hpp"

#include <array>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/text_cursor.hpp"

namespace rthdist::io {

Result<PointCloud> readObj(std::string_view bytes, const std::string& path) {
    std::vector<glm::dvec3> points;
    TextCursor cursor(bytes);
    std::string_view line;
    while (cursor.nextLine(line)) {
        const std::string_view body = trimBlank(line);
        // Only geometric vertices: "v " and "v\t" (not vn, vt, vp).
        if (body.size() < 2 || body[0] != 'v' || (body[1] != ' ' && body[1] != '\t')) continue;
        std::array<std::string_view, 4> tok{};
        const size_t n = splitTokens(body.substr(1), tok.data(), tok.size());
        if (n < 3) {
            return badInput(path, lineWhere(cursor.line()),
                            "vertex line with " + std::to_string(n) + " coordinate(s)");
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
