#include "io/xyz_reader.hpp"

#include "io/text_chunks.hpp"

namespace rthdist::io {
namespace {

bool isPointLine(std::string_view line) {
    const std::string_view body = trimBlank(line);
    return !body.empty() && body.front() != '#' && !body.starts_with("//");
}

constexpr PointLineFormat kXyzPoints{
    .isItem = &isPointLine,
    .shortestLine = 6,  // "0 0 0" and its line end
    .separators = ",;",
    .tooFew = {"expected 'x y z', found ", " column(s)"},
};

}  // namespace

Result<PointCloud> readXyz(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    return readPointLines<kXyzPoints>(bytes, path, plan);
}

}  // namespace rthdist::io
