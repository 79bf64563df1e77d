// Reads a whole file into memory; a ".gz" file is gunzipped on the way.
#pragma once

#include <string>

#include "io/gzip_inflate.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// Fails (kBadInput, message names the path) for a missing file, a directory,
// an unreadable file, a corrupt or truncated gzip stream and one that
// inflates beyond its cap (gzip_inflate.hpp; gzipBound: the format's header
// check). An empty file is returned as an empty string; the caller decides
// whether that is an error.
[[nodiscard]] Result<std::string> readFileBytes(const std::string& path, InflatedBound gzipBound = nullptr);

}  // namespace rthdist::io
