#include "io/obj_reader.hpp"

#include <charconv>

#include "io/face_list.hpp"
#include "io/text_chunks.hpp"

namespace rthdist::io {
namespace {

// Only geometric vertices: "v " and "v\t" (not vn, vt, vp).
bool isVertexLine(std::string_view line) {
    const std::string_view body = trimBlank(line);
    return body.size() >= 2 && body[0] == 'v' && (body[1] == ' ' || body[1] == '\t');
}

constexpr PointLineFormat kObjVertices{
    .isItem = &isVertexLine,
    .shortestLine = 8,  // "v 0 0 0" and its line end
    .skip = 1,          // the "v"
    .tooFew = {"vertex line with ", " coordinate(s)"},
};

bool isFaceLine(std::string_view body) {
    return body.size() >= 2 && body[0] == 'f' && (body[1] == ' ' || body[1] == '\t');
}

// One face vertex "i[/t[/n]]" as a 0-based index; false when i is not a
// nonzero integer. Negative i counts back from the vertices defined so far.
bool faceVertex(std::string_view token, uint64_t definedSoFar, int64_t& out) {
    token = token.substr(0, token.find('/'));
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    int64_t i = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), i);
    if (token.empty() || ec != std::errc() || ptr != token.data() + token.size() || i == 0) return false;
    out = i > 0 ? i - 1 : int64_t(definedSoFar) + i;
    return true;
}

}  // namespace

Result<std::vector<uint32_t>> readObjFaces(std::string_view bytes, const std::string& path,
                                           uint64_t vertexCount) {
    FaceList faces(vertexCount);
    TextCursor cursor(bytes);
    uint64_t defined = 0;
    uint64_t face = 0;
    std::vector<int64_t> polygon;
    std::string_view line;
    while (cursor.nextLine(line)) {
        const std::string_view body = trimBlank(line);
        if (isVertexLine(body)) {
            ++defined;
            continue;
        }
        if (!isFaceLine(body)) continue;
        polygon.clear();
        std::optional<Error> bad;
        forEachToken(body.substr(1), &isBlank, [&](size_t, size_t begin, size_t end) {
            const std::string_view token = body.substr(1 + begin, end - begin);
            int64_t v = 0;
            if (bad) return;
            if (!faceVertex(token, defined, v)) {
                bad = badInput(path, lineWhere(cursor.line()),
                               "face " + std::to_string(face) + ": '" + std::string(token) +
                                   "' is not a vertex index (1-based, or negative: relative)");
            }
            polygon.push_back(v);
        });
        if (bad) return *bad;
        if (auto err = faces.addPolygon(path, lineWhere(cursor.line()), face, polygon)) return *err;
        ++face;
    }
    return faces.take();
}

Result<PointCloud> readObj(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    return readPointLines<kObjVertices>(bytes, path, plan);
}

}  // namespace rthdist::io
