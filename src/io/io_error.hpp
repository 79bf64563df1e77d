// Builds the one error shape every loader returns: "<path>: <where>: <what>".
#pragma once

#include <cstdint>
#include <optional>
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

// The error when `count` records of `recordBytes` each do not fit in the
// `available` bytes that start at byte `at` (compared without overflow):
// "<subject>declares <count> points of <recordBytes> bytes, but only
// <available> bytes <rest>"; std::nullopt when they fit.
[[nodiscard]] inline std::optional<Error> checkRecordsFit(std::string_view path, size_t at,
                                                          std::string_view subject, uint64_t count,
                                                          uint64_t recordBytes, uint64_t available,
                                                          std::string_view rest) {
    if (count <= available / recordBytes) return std::nullopt;
    std::string what(subject);
    what.append("declares " + std::to_string(count) + " points of " + std::to_string(recordBytes) +
                " bytes, but only " + std::to_string(available) + " bytes ");
    what.append(rest);
    return badInput(path, offsetWhere(at), what);
}

// "'<token>' is not a number" (built by append: GCC 12's -Wrestrict misfires
// on "'" + std::string(...)).
[[nodiscard]] inline std::string notANumber(std::string_view token) {
    std::string s = "'";
    s.append(token).append("' is not a number");
    return s;
}

}  // namespace rthdist::io
