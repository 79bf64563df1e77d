// Reads a whole file into memory; a ".gz" file is gunzipped on the way.
#pragma once

#include <string>

#include "rthdist/result.hpp"

namespace rthdist::io {

// Fails (kBadInput, message names the path) for a missing file, a directory,
// an unreadable file and a corrupt or truncated gzip stream. An empty file is
// returned as an empty string; the caller decides whether that is an error.
[[nodiscard]] Result<std::string> readFileBytes(const std::string& path);

}  // namespace rthdist::io
