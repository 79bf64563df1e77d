// PLY (ascii, binary_little_endian, binary_big_endian): the x/y/z of the vertex element;
// every other property, list and element is skipped. Elements after the
// vertex element are not read.
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "rthdist/result.hpp"

namespace rthdist::io {

// bytes: the whole (already gunzipped) file; path names it in error messages.
[[nodiscard]] Result<std::vector<glm::vec3>> readPly(std::string_view bytes, const std::string& path);

}  // namespace rthdist::io
