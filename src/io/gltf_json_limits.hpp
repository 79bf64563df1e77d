// A pre-check of glTF JSON before tinygltf parses it: tinygltf's value parser
// recurses once per nesting level (16,000 nested arrays overflow the stack)
// and every top-level object becomes a struct of up to 2 KB (a 12 MB file of
// empty nodes took 2.2 GB). One linear scan, strings skipped, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "rthdist/result.hpp"

namespace rthdist::io {

// Deepest nesting of arrays and objects.
inline constexpr size_t kMaxGltfJsonDepth = 256;
// Array elements plus object members, at any depth.
inline constexpr uint64_t kMaxGltfJsonValues = 2'000'000;
// Objects in the top-level arrays (nodes, meshes, accessors, materials...).
inline constexpr uint64_t kMaxGltfTopLevelObjects = 500'000;

// json: the JSON text; offset: where it starts in the file (a .glb's JSON
// chunk starts at byte 20), for the byte offset named in the error.
[[nodiscard]] std::optional<Error> checkGltfJsonLimits(std::string_view json, size_t offset,
                                                       const std::string& path);

}  // namespace rthdist::io
