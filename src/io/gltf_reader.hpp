// glTF 2.0 (.gltf with embedded or external buffers, .glb): POSITION of every
// primitive of every mesh instanced by the scene's nodes, node transforms
// (matrix or TRS) composed down the hierarchy. The default scene is used when
// set, else every scene. Images are never decoded. Sparse accessors and
// morph targets are not supported (sparse POSITION is an error).
//
// Limits, checked before the memory is spent: the JSON (gltf_json_limits.hpp)
// before tinygltf parses it; external buffers only as regular files inside
// the file's directory (gltf_file_access.hpp); kMaxGltfInstancedPoints
// points and kMaxGltfNodeVisits node instances over all scenes, counted
// before any point is read.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

inline constexpr uint64_t kMaxGltfInstancedPoints = 100'000'000;
inline constexpr uint64_t kMaxGltfNodeVisits = 10'000'000;
inline constexpr uint64_t kMaxGltfInstancedTriangles = 200'000'000;

// bytes: the whole file (".glb" is recognised by its "glTF" magic); external
// buffers are resolved relative to path's directory.
[[nodiscard]] Result<PointArray<glm::vec3>> readGltf(std::string_view bytes, const std::string& path);

// The points as readGltf reads them and the triangles of every primitive of
// mode TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN (its indices accessor, or
// its vertices in order; an index past the primitive's POSITION count is an
// error naming the node and the accessor), indices into those points.
struct GltfMesh {
    PointArray<glm::vec3> points;
    std::vector<uint32_t> triangles;
};
[[nodiscard]] Result<GltfMesh> readGltfMesh(std::string_view bytes, const std::string& path);

// The gunzip header check (gzip_inflate.hpp): a .glb inflates to the length
// in its header; a .gltf (JSON): no bound.
[[nodiscard]] Result<uint64_t> glbInflatedBound(std::string_view head, bool whole, const std::string& path);

}  // namespace rthdist::io
