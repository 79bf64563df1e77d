// PCD (ascii, binary): the x/y/z fields, any SIZE/TYPE/COUNT; not binary_compressed.
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// bytes: the whole (already gunzipped) file; path names it in error messages.
[[nodiscard]] Result<PointCloud> readPcd(std::string_view bytes, const std::string& path);

}  // namespace rthdist::io
