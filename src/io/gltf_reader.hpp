// glTF 2.0 (.gltf with embedded or external buffers, .glb): POSITION of every
// primitive of every mesh instanced by the scene's nodes, node transforms
// (matrix or TRS) composed down the hierarchy. The default scene is used when
// set, else every scene. Images are never decoded. Sparse accessors and
// morph targets are not supported (sparse POSITION is an error).
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::io {

// bytes: the whole file (".glb" is recognised by its "glTF" magic); external
// buffers are resolved relative to path's directory.
[[nodiscard]] Result<std::vector<glm::vec3>> readGltf(std::string_view bytes, const std::string& path);

}  // namespace rthdist::io
