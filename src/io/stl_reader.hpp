// STL, binary (chosen when the size matches 84 + 50 * facets, or when the
// file holds a NUL byte, whatever its header says) or ascii ("solid", text
// only): every facet vertex in file order, shared vertices repeated.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// bytes: the whole (already gunzipped) file; path names it in error messages.
[[nodiscard]] Result<PointCloud> readStl(std::string_view bytes, const std::string& path);

// The gunzip header check (gzip_inflate.hpp): a binary STL inflates to
// 84 + 50 * facets bytes; ascii: no bound.
[[nodiscard]] Result<uint64_t> stlInflatedBound(std::string_view head, bool whole, const std::string& path);

}  // namespace rthdist::io
