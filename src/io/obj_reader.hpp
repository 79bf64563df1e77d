// Wavefront OBJ: the "v x y z" lines (points), and the "f" lines (faces);
// everything else is ignored.
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
[[nodiscard]] Result<PointCloud> readObj(std::string_view bytes, const std::string& path,
                                         const ChunkPlan& plan = {});

// The triangles of the "f" lines (face_list.hpp), in one serial pass:
// "f v v v ...", each v as "i", "i/t", "i//n" or "i/t/n"; i is 1-based, or
// negative (relative to the "v" lines before the face). vertexCount: the
// file's vertices (readObj's count).
[[nodiscard]] Result<std::vector<uint32_t>> readObjFaces(std::string_view bytes, const std::string& path,
                                                         uint64_t vertexCount);

}  // namespace rthdist::io
