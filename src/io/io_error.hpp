// Builds the one error shape every loader returns: "<path>: <where>: <what>".
#pragma once

#include <string>
#include <string_view>

#include "rthdist/result.hpp"

namespace rthdist::io {

// where names the place inside the file: "line 12", "vertex 7",
// "byte offset 96", "element face", "header"...
[[nodiscard]] inline Error badInput(std::string_view path, std::string_view where, std::string_view what) {
    std::string message;
    message.reserve(path.size() + where.size() + what.size() + 4);
    message.append(path).append(": ").append(where).append(": ").append(what);
    return Error{ErrorCode::kBadInput, std::move(message)};
}

[[nodiscard]] inline std::string lineWhere(size_t line) { return "line " + std::to_string(line); }

[[nodiscard]] inline std::string offsetWhere(size_t offset) {
    return "byte offset " + std::to_string(offset);
}

// "'<token>' is not a number" (built by append: GCC 12's -Wrestrict misfires
// on "'" + std::string(...)).
[[nodiscard]] inline std::string notANumber(std::string_view token) {
    std::string s = "'";
    s.append(token).append("' is not a number");
    return s;
}

}  // namespace rthdist::io
