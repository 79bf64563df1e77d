// OFF / COFF / NOFF / CNOFF / STOFF (ascii): the vertex block and the face
// block; '#' comments.
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
[[nodiscard]] Result<PointCloud> readOff(std::string_view bytes, const std::string& path,
                                         const ChunkPlan& plan = {});

// The triangles of the face block (face_list.hpp): the header's face count
// of content lines "n i0 .. in-1" (0-based indices; a colour after them is
// ignored) after the vertices. vertexCount: readOff's count.
[[nodiscard]] Result<std::vector<uint32_t>> readOffFaces(std::string_view bytes, const std::string& path,
                                                         uint64_t vertexCount);

}  // namespace rthdist::io
