// rthdist — point-set loaders.
//
// Formats (chosen by extension, case-insensitive; ".gz" is unwrapped first):
//   .ply  ascii, binary_little_endian, binary_big_endian; vertex x/y/z as any
//         numeric type (float/double/int...); other vertex properties, list
//         properties and other elements (faces, tristrips, range_grid) skipped.
//   .xyz / .txt  one "x y z" per line (extra columns ignored, '#' comments).
//   .obj  "v x y z" lines only.
//   .gltf / .glb  POSITION of every primitive of every mesh instanced by the
//         scene's nodes, with node transforms applied (tinygltf).
//   .stl  ascii and binary (every facet vertex, duplicates kept)
//   .off  OFF / COFF / NOFF headers, vertices only
//   .pcd  ascii and binary (x y z fields, any size/type), not binary_compressed
//
// Contract: on success, at least one point and every coordinate finite. Every
// failure is ErrorCode::kBadInput with a message "<path>: <where>: <what>"
// (where = line N, vertex N, byte offset N, element name...). Declared counts
// are checked against the file size before anything is allocated, so a lying
// header cannot cause a huge allocation.
//
// Precision: decimal text is converted straight to the nearest float
// (std::from_chars); double and integer inputs are rounded to float.
// Limits: PLY elements after the vertex element are not read; a glTF mesh
// instanced by several nodes gives its points once per instance; NaN points
// (e.g. in organized PCD clouds) are rejected, not dropped. Reentrant: no
// shared state, safe to call from several threads.
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::io {

[[nodiscard]] Result<std::vector<glm::vec3>> loadPoints(const std::string& path);

// Writes a binary little-endian PLY with float x/y/z vertices only.
[[nodiscard]] Result<bool> writePlyPoints(const std::string& path, const std::vector<glm::vec3>& points);

}  // namespace rthdist::io
