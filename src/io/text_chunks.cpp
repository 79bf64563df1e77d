#include "io/text_chunks.hpp"

#include <algorithm>

namespace rthdist::io {
namespace {

// The first line start at or after pos: just past the next line end ("\r\n"
// as one), or the end of the text.
size_t nextLineStart(std::string_view text, size_t pos) {
    while (pos < text.size() && text[pos] != '\n' && text[pos] != '\r') ++pos;
    if (pos >= text.size()) return text.size();
    if (text[pos] == '\r' && pos + 1 < text.size() && text[pos + 1] == '\n') return pos + 2;
    return pos + 1;
}

}  // namespace

TextChunks splitLines(std::string_view text, size_t firstLine, ItemLine isItem, const ChunkPlan& plan) {
    TextChunks out;
    out.firstLine = firstLine;
    for (size_t begin = 0; begin < text.size();) {
        // The line that holds the chunk's last byte ends it.
        const size_t last = plan.bytes() - 1 < text.size() - begin ? begin + plan.bytes() - 1 : text.size();
        const size_t end = nextLineStart(text, last);
        out.chunks.push_back(TextChunk{begin, end});
        begin = end;
    }
    (void)forEachChunk(out.chunks.size(), plan, [&](size_t c) -> std::optional<Error> {
        TextChunk& chunk = out.chunks[c];
        TextCursor cursor(text.substr(chunk.begin, chunk.end - chunk.begin), 1);
        std::string_view line;
        while (cursor.nextLine(line)) {
            ++chunk.lines;
            if (isItem(line)) ++chunk.items;
        }
        return std::nullopt;
    });
    for (TextChunk& chunk : out.chunks) {
        chunk.firstLine = firstLine + out.lines;
        chunk.firstItem = out.items;
        out.lines += chunk.lines;
        out.items += chunk.items;
    }
    return out;
}

void keepItems(TextChunks& chunks, std::string_view text, ItemLine isItem, uint64_t maxItems) {
    if (chunks.items <= maxItems) return;
    std::vector<TextChunk>& list = chunks.chunks;
    if (maxItems == 0) {
        list.clear();
        return;
    }
    // The chunk that holds item maxItems - 1 (there are more items, so one does).
    size_t last = 0;
    while (list[last].firstItem + list[last].items < maxItems) ++last;
    TextChunk& chunk = list[last];
    TextCursor cursor(text.substr(chunk.begin, chunk.end - chunk.begin), chunk.firstLine);
    std::string_view line;
    uint64_t items = 0;
    size_t lines = 0;
    while (chunk.firstItem + items < maxItems && cursor.nextLine(line)) {
        ++lines;
        if (isItem(line)) ++items;
    }
    chunk.end = chunk.begin + cursor.offset();
    chunk.lines = lines;
    chunk.items = items;
    list.resize(last + 1);
}

}  // namespace rthdist::io
