#include "io/gltf_json_limits.hpp"

#include <array>

#include "io/io_error.hpp"

namespace rthdist::io {

std::optional<Error> checkGltfJsonLimits(std::string_view json, size_t offset, const std::string& path) {
    std::array<char, kMaxGltfJsonDepth + 1> open{};  // '{' or '[' per level; open[0] unused
    size_t depth = 0;
    uint64_t values = 0;
    uint64_t topLevelObjects = 0;
    bool inString = false;
    for (size_t i = 0; i < json.size(); ++i) {
        const char c = json[i];
        if (inString) {
            if (c == '\\') {
                ++i;  // the escaped character cannot end the string
            } else if (c == '"') {
                inString = false;
            }
            continue;
        }
        switch (c) {
            case '"': inString = true; break;
            case '{':
            case '[':
                if (++depth > kMaxGltfJsonDepth) {
                    return badInput(path, offsetWhere(offset + i),
                                    "JSON nested deeper than " + std::to_string(kMaxGltfJsonDepth) +
                                        " levels (limit of this loader)");
                }
                open[depth] = c;
                ++values;
                if (c == '{' && depth == 3 && open[1] == '{' && open[2] == '[' &&
                    ++topLevelObjects > kMaxGltfTopLevelObjects) {
                    return badInput(path, offsetWhere(offset + i),
                                    "more than " + std::to_string(kMaxGltfTopLevelObjects) +
                                        " glTF objects (nodes, meshes, accessors...; limit of this loader)");
                }
                break;
            case '}':
            case ']':
                if (depth > 0) --depth;
                break;
            case ',': ++values; break;
            default: break;
        }
        if (values > kMaxGltfJsonValues) {
            return badInput(
                path, offsetWhere(offset + i),
                "more than " + std::to_string(kMaxGltfJsonValues) + " JSON values (limit of this loader)");
        }
    }
    return std::nullopt;
}

}  // namespace rthdist::io
