// PLY (ascii, binary_little_endian, binary_big_endian): the x/y/z of the
// vertex element; every other property, list and element is skipped, but
// every declared element must be in the file (ascii: one item per line with
// its exact number of values; binary: item by item to the end of the file).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/parallel_chunks.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// Most properties one element may declare (the 3D Gaussian splats' 62, a
// point's feature vector, ...): a header past it is refused, not parsed.
inline constexpr size_t kMaxPlyPropertiesPerElement = 65536;

// bytes: the whole (already gunzipped) file; path names it in error messages.
// plan: threads and chunk size of the parallel parts (the result does not
// depend on it).
[[nodiscard]] Result<PointCloud> readPly(std::string_view bytes, const std::string& path,
                                         const ChunkPlan& plan = {});

// The triangles of the element "face" (face_list.hpp), read after readPly
// has read and checked the whole body: its list property "vertex_indices"
// (or "vertex_index"), any integer type. vertexCount: readPly's count.
[[nodiscard]] Result<std::vector<uint32_t>> readPlyFaces(std::string_view bytes, const std::string& path,
                                                         uint64_t vertexCount);

// The gunzip header check (gzip_inflate.hpp): a binary PLY inflates to at
// most its header plus every declared item at its largest; ascii: no bound.
[[nodiscard]] Result<uint64_t> plyInflatedBound(std::string_view head, bool whole, const std::string& path);

}  // namespace rthdist::io
