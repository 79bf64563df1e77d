// XYZ text: one point per line, the first three columns (separated by blanks,
// ',' or ';'); blank lines and lines starting with '#' or '//' are skipped.
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "io/parallel_chunks.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// bytes: the whole (already gunzipped) file; path names it in error messages.
// plan: threads and chunk size of the parallel parse (the result does not
// depend on it).
[[nodiscard]] Result<PointCloud> readXyz(std::string_view bytes, const std::string& path,
                                         const ChunkPlan& plan = {});

}  // namespace rthdist::io
