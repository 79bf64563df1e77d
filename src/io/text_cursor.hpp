// Forward scanning of text (whole file in memory) by line or by
// whitespace-separated token, counting lines for error messages.
//
// Line ends are "\n", "\r\n" and a lone "\r" (classic Mac OS): a file saved
// with CR-only line ends must not read as one long line. A UTF-8 byte order
// mark at the start of a file is not text and is skipped.
#pragma once

#include <cstddef>
#include <cstring>
#include <string_view>

namespace rthdist::io {

inline constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

[[nodiscard]] constexpr bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

[[nodiscard]] inline std::string_view trimBlank(std::string_view s) {
    while (!s.empty() && isBlank(s.front())) s.remove_prefix(1);
    while (!s.empty() && isBlank(s.back())) s.remove_suffix(1);
    return s;
}

// Bytes of a UTF-8 byte order mark at the start of text (0 or 3).
[[nodiscard]] inline size_t bomLength(std::string_view text) { return text.starts_with(kUtf8Bom) ? 3 : 0; }

// Calls visit(n, begin, end) for the n-th run of characters of s that are
// not separators (isSep), s[begin, end), in order; returns how many there
// are. Offsets, not a substring: a caller that keeps only some tokens
// builds only those (per-line parsing is hot).
template <class IsSep, class Visit>
inline size_t forEachToken(std::string_view s, IsSep isSep, Visit&& visit) {
    size_t n = 0;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && isSep(s[i])) ++i;
        if (i == s.size()) break;
        const size_t start = i;
        while (i < s.size() && !isSep(s[i])) ++i;
        visit(n, start, i);
        ++n;
    }
    return n;
}

// Splits s at blanks (and at any of extraSeparators) into at most maxTokens
// tokens; returns how many were found, counting past maxTokens.
inline size_t splitTokens(std::string_view s, std::string_view* tokens, size_t maxTokens,
                          std::string_view extraSeparators = {}) {
    auto isSep = [&](char c) {
        if (isBlank(c)) return true;
        for (char e : extraSeparators) {
            if (c == e) return true;
        }
        return false;
    };
    return forEachToken(s, isSep, [&](size_t n, size_t begin, size_t end) {
        if (n < maxTokens) tokens[n] = s.substr(begin, end - begin);
    });
}

class TextCursor {
public:
    // A whole file: a leading UTF-8 byte order mark is skipped (offsets stay
    // offsets into file).
    explicit TextCursor(std::string_view file) : m_text(file), m_pos(bomLength(file)) {}

    // A part of a file; firstLine: the line number of text's first character.
    TextCursor(std::string_view text, size_t firstLine)
        : m_text(text), m_nextLine(firstLine), m_line(firstLine) {}

    // Next line without its terminator ("\n", "\r\n" or "\r"); false at the end.
    bool nextLine(std::string_view& line) {
        if (m_pos >= m_text.size()) return false;
        const size_t end = lineEnd();
        line = m_text.substr(m_pos, end - m_pos);
        m_pos = end;
        skipLineEnd();
        m_line = m_nextLine++;
        return true;
    }

    // Next blank-separated token; empty at the end of the text.
    std::string_view nextToken() {
        while (m_pos < m_text.size() && isBlank(m_text[m_pos])) {
            if (m_text[m_pos] == '\n' || m_text[m_pos] == '\r') {
                skipLineEnd();
                ++m_nextLine;
            } else {
                ++m_pos;
            }
        }
        const size_t start = m_pos;
        while (m_pos < m_text.size() && !isBlank(m_text[m_pos])) ++m_pos;
        m_line = m_nextLine;
        return m_text.substr(start, m_pos - start);
    }

    // Line of the last line or token returned.
    [[nodiscard]] size_t line() const { return m_line; }
    [[nodiscard]] size_t offset() const { return m_pos; }
    [[nodiscard]] size_t remaining() const { return m_text.size() - m_pos; }

private:
    static constexpr size_t kUnknown = ~size_t(0);

    // Where the line at m_pos ends: the next '\n' (cached, so that a file
    // with "\r" line ends only is searched for one once), or a '\r' before
    // it. Two memchr calls per line instead of a test per byte.
    size_t lineEnd() {
        const char* base = m_text.data();
        if (m_newline == kUnknown || m_newline < m_pos) {
            const void* nl = std::memchr(base + m_pos, '\n', m_text.size() - m_pos);
            m_newline =
                nl != nullptr ? static_cast<size_t>(static_cast<const char*>(nl) - base) : m_text.size();
        }
        const void* cr = std::memchr(base + m_pos, '\r', m_newline - m_pos);
        return cr != nullptr ? static_cast<size_t>(static_cast<const char*>(cr) - base) : m_newline;
    }

    // At a line end (or the end of the text): steps over "\r\n", "\r" or "\n".
    void skipLineEnd() {
        if (m_pos >= m_text.size()) return;
        if (m_text[m_pos] == '\r') {
            ++m_pos;
            if (m_pos < m_text.size() && m_text[m_pos] == '\n') ++m_pos;
        } else if (m_text[m_pos] == '\n') {
            ++m_pos;
        }
    }

    std::string_view m_text;
    size_t m_pos = 0;
    size_t m_nextLine = 1;
    size_t m_line = 1;
    size_t m_newline = kUnknown;  // position of the next '\n' at or after m_pos, or the text's size
};

}  // namespace rthdist::io
