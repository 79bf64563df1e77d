#include "io/obj_reader.hpp"

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

}  // namespace

Result<PointCloud> readObj(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    return readPointLines<kObjVertices>(bytes, path, plan);
}

}  // namespace rthdist::io
