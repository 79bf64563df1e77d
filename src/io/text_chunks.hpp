// Text bodies parsed in parallel: the text is cut after line ends into
// chunks, a first parallel pass counts each chunk's lines and item lines
// (the lines a format reads: points, vertices, rows), prefix sums give every
// chunk the file line number of its first line and the index of its first
// item, and a second parallel pass parses each chunk straight into the
// output at that index. Errors name the same line and item as a serial
// parse, and the first chunk's error wins, so the message is the one a
// serial parse gives for the first bad place in the file.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/parallel_chunks.hpp"
#include "io/text_cursor.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

// Which lines of a format are items (the same test in both passes).
using ItemLine = bool (*)(std::string_view line);

struct TextChunk {
    size_t begin = 0;        // byte offsets into the text
    size_t end = 0;          // after the chunk's last line end
    size_t firstLine = 0;    // file line number of its first line
    size_t lines = 0;        // lines in it
    uint64_t firstItem = 0;  // items in the text before it
    uint64_t items = 0;      // item lines in it
};

struct TextChunks {
    std::vector<TextChunk> chunks;
    size_t firstLine = 0;  // of the text
    size_t lines = 0;      // in the whole text (keepItems leaves it)
    uint64_t items = 0;    // in the whole text (keepItems leaves it)

    // Line number of the text's last line; firstLine - 1 when it has none
    // (what a serial TextCursor's line() says after its last line).
    [[nodiscard]] size_t lastLine() const { return firstLine + lines - 1; }
};

// Cuts text, whose first line has number firstLine, after line ends
// ("\n", "\r\n", "\r": never between the two bytes of "\r\n") into chunks
// of about plan.bytes() bytes, and counts each chunk's lines and items in
// parallel.
[[nodiscard]] TextChunks splitLines(std::string_view text, size_t firstLine, ItemLine isItem,
                                    const ChunkPlan& plan);

// Keeps the chunks up to the line of item maxItems - 1 (that chunk then ends
// after this line); nothing changes when the text has no more than maxItems
// items. maxItems 0 keeps no chunk.
void keepItems(TextChunks& chunks, std::string_view text, ItemLine isItem, uint64_t maxItems);

// Calls parse(chunk, cursor) for every chunk, in parallel; cursor walks the
// chunk's lines with their file line numbers. parse returns the chunk's
// first error or std::nullopt; the error of the first chunk that has one is
// returned.
template <class Parse>
std::optional<Error> parseChunks(const TextChunks& chunks, std::string_view text, const ChunkPlan& plan,
                                 Parse&& parse) {
    return forEachChunk(chunks.chunks.size(), plan, [&](size_t c) -> std::optional<Error> {
        const TextChunk& chunk = chunks.chunks[c];
        TextCursor cursor(text.substr(chunk.begin, chunk.end - chunk.begin), chunk.firstLine);
        return parse(chunk, cursor);
    });
}

// A text format with one point per item line, x y z its first three
// tokens (XYZ, OBJ).
struct PointLineFormat {
    ItemLine isItem;
    // The fewest bytes an item line takes with its line end: when the text
    // holds more item lines than that allows, one of them is bad, and it is
    // found before anything is allocated for all of them.
    size_t shortestLine;
    size_t skip = 0;                   // characters before the coordinates of a trimmed item line
    std::string_view separators = {};  // between tokens, besides blanks
    // The error of an item line with n < 3 tokens: tooFew[0] n tooFew[1].
    std::array<std::string_view, 2> tooFew;
};

// Whether a line separates its values both by blanks alone and by runs
// holding a comma ("1,5 2,5 3,5" has decimal commas, which would read as
// the values 1, 5, 2): such a line is refused rather than guessed. Other
// separators (';') mix with blanks freely.
inline bool mixesBlanksAndCommas(std::string_view s) {
    bool blankRun = false, commaRun = false;
    for (size_t i = 0; i < s.size();) {
        if (!isBlank(s[i]) && s[i] != ',') {
            ++i;
            continue;
        }
        bool comma = false;
        for (; i < s.size() && (isBlank(s[i]) || s[i] == ','); ++i) comma = comma || s[i] == ',';
        (comma ? commaRun : blankRun) = true;
    }
    return blankRun && commaRun;
}

// The points of such a format (a leading UTF-8 byte order mark skipped), in
// parallel chunks; an error names the file line of the first bad item line.
// The format is a template argument so that its separators and its item
// test are constants in the per-line loop.
template <const PointLineFormat& format>
Result<PointCloud> readPointLines(std::string_view bytes, const std::string& path, const ChunkPlan& plan) {
    const std::string_view text = bytes.substr(bomLength(bytes));
    const TextChunks chunks = splitLines(text, 1, format.isItem, plan);
    PointArray<glm::dvec3> points;
    auto parse = [&](const TextChunk& chunk, TextCursor& cursor) -> std::optional<Error> {
        uint64_t k = chunk.firstItem;
        std::string_view line;
        while (cursor.nextLine(line)) {
            if (!format.isItem(line)) continue;
            std::array<std::string_view, 3> tok{};
            const std::string_view body = trimBlank(line).substr(format.skip);
            if (format.separators.find(',') != std::string_view::npos && mixesBlanksAndCommas(body))
                return badInput(path, lineWhere(cursor.line()),
                                "values separated both by blanks alone and by commas (decimal commas?): "
                                "use one separator");
            const size_t n = splitTokens(body, tok.data(), tok.size(), format.separators);
            if (n < 3) {
                std::string what(format.tooFew[0]);
                what.append(std::to_string(n)).append(format.tooFew[1]);
                return badInput(path, lineWhere(cursor.line()), what);
            }
            glm::dvec3 p;
            if (const auto bad = parsePoint(tok.data(), p))
                return badInput(path, lineWhere(cursor.line()), notANumber(*bad));
            if (!points.empty()) points[k] = p;
            ++k;
        }
        return std::nullopt;
    };
    if (chunks.items > (text.size() + 1) / format.shortestLine) {
        if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    }
    points.resize(static_cast<size_t>(chunks.items), glm::dvec3(0.0));
    if (auto err = parseChunks(chunks, text, plan, parse)) return *err;
    return PointCloud{Scalar::kFloat64, {}, std::move(points)};
}

}  // namespace rthdist::io
