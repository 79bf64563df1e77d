// Decompresses a gzip stream (one or more concatenated members) with zlib.
#pragma once

#include <string>
#include <string_view>

#include "rthdist/result.hpp"

namespace rthdist::io {

// path only names the file in error messages. A stream that ends before its
// trailer, or has a bad CRC, is an error naming the compressed byte offset.
[[nodiscard]] Result<std::string> gunzip(std::string_view compressed, const std::string& path);

}  // namespace rthdist::io
