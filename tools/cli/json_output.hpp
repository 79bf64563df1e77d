// JSON documents of the command-line tools (--json of rthdist and
// rthdist-masks, rthdist-bench's record): built as nlohmann::ordered_json
// (members stay in the order they are set) and written by jsonText in the
// layout the tools have always printed, which nlohmann's dump() does not
// reproduce:
//
// - numbers: integers as themselves; doubles as the shortest text that reads
//   back to the same double (std::to_chars: 1, 0.1, 1e-40), a float stored
//   as its exact double; NaN and infinities as null;
// - strings: RFC 8259 escapes ('"', '\\', every control character and DEL);
//   bytes that are not well-formed UTF-8 (file paths on Linux are arbitrary
//   bytes) become the escape \ufffd, one per byte, so the output always parses;
// - kIndented: two spaces per level, one member or item per line, except
//   arrays of numbers, which stay on one line ("[0.5, 1, 2]");
//   kCompact: one line, "," between members, ", " between items.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace rthdist::cli {

using Json = nlohmann::ordered_json;

enum class JsonLayout { kIndented, kCompact };

// The document's text, without a trailing newline.
[[nodiscard]] std::string jsonText(const Json& document, JsonLayout layout = JsonLayout::kIndented);

}  // namespace rthdist::cli
