// Forward scanning of text (whole file in memory) by line or by
// whitespace-separated token, counting lines for error messages.
#pragma once

#include <cstddef>
#include <string_view>

namespace rthdist::io {

[[nodiscard]] constexpr bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

[[nodiscard]] inline std::string_view trimBlank(std::string_view s) {
    while (!s.empty() && isBlank(s.front())) s.remove_prefix(1);
    while (!s.empty() && isBlank(s.back())) s.remove_suffix(1);
    return s;
}

// Splits s at blanks (and at any of extraSeparators) into at most maxTokens
// tokens; returns how many were found, counting past maxTokens.
inline size_t splitTokens(std::string_view s, std::string_view* tokens, size_t maxTokens,
                          std::string_view extraSeparators = {}) {
    auto isSep = [&](char c) { return isBlank(c) || extraSeparators.find(c) != std::string_view::npos; };
    size_t n = 0;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && isSep(s[i])) ++i;
        if (i == s.size()) break;
        const size_t start = i;
        while (i < s.size() && !isSep(s[i])) ++i;
        if (n < maxTokens) tokens[n] = s.substr(start, i - start);
        ++n;
    }
    return n;
}

class TextCursor {
public:
    // firstLine: the line number of text's first character in the file.
    explicit TextCursor(std::string_view text, size_t firstLine = 1)
        : m_text(text), m_nextLine(firstLine), m_line(firstLine) {}

    // Next line without its terminator ("\n" or "\r\n"); false at the end.
    bool nextLine(std::string_view& line) {
        if (m_pos >= m_text.size()) return false;
        const size_t nl = m_text.find('\n', m_pos);
        const size_t end = nl == std::string_view::npos ? m_text.size() : nl;
        line = m_text.substr(m_pos, end - m_pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        m_pos = nl == std::string_view::npos ? m_text.size() : nl + 1;
        m_line = m_nextLine++;
        return true;
    }

    // Next blank-separated token; empty at the end of the text.
    std::string_view nextToken() {
        while (m_pos < m_text.size() && isBlank(m_text[m_pos])) {
            if (m_text[m_pos] == '\n') ++m_nextLine;
            ++m_pos;
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
    std::string_view m_text;
    size_t m_pos = 0;
    size_t m_nextLine;
    size_t m_line;
};

}  // namespace rthdist::io
