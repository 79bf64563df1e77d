#include "cli/json_output.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

namespace rthdist::cli {

namespace {

// Length of the well-formed UTF-8 sequence at text[i], 0 when it is not one
// (overlong forms, surrogates and code points above U+10FFFF are rejected).
size_t utf8SequenceLength(std::string_view text, size_t i) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char c = byte(i);
    size_t len = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (c >= 0xC2 && c <= 0xDF) {
        len = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
        len = 3;
        if (c == 0xE0) lo = 0xA0;
        if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
        len = 4;
        if (c == 0xF0) lo = 0x90;
        if (c == 0xF4) hi = 0x8F;
    } else {
        return 0;
    }
    if (i + len > text.size()) return 0;
    if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
    for (size_t k = 2; k < len; ++k) {
        if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
    }
    return len;
}

void appendQuoted(std::string& out, std::string_view text) {
    static constexpr char kHex[] = "0123456789abcdef";
    out += '"';
    for (size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x80) {
            const size_t len = utf8SequenceLength(text, i);
            out.append(len == 0 ? std::string_view("\\ufffd") : text.substr(i, len));
            i += std::max<size_t>(len, 1);
            continue;
        }
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (c < 0x20 || c == 0x7F) {
                    out += "\\u00";
                    out += kHex[c >> 4];
                    out += kHex[c & 0xF];
                } else {
                    out += static_cast<char>(c);
                }
        }
        ++i;
    }
    out += '"';
}

template <class Number>
void appendNumber(std::string& out, Number v) {
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, res.ptr);
}

class Writer {
public:
    Writer(std::string& out, JsonLayout layout) : m_out(out), m_compact(layout == JsonLayout::kCompact) {}

    void write(const Json& j, size_t depth) {
        switch (j.type()) {
            case Json::value_t::object: writeObject(j, depth); break;
            case Json::value_t::array: writeArray(j, depth); break;
            case Json::value_t::string: appendQuoted(m_out, j.get_ref<const std::string&>()); break;
            case Json::value_t::boolean: m_out += j.get<bool>() ? "true" : "false"; break;
            case Json::value_t::number_integer: appendNumber(m_out, j.get<int64_t>()); break;
            case Json::value_t::number_unsigned: appendNumber(m_out, j.get<uint64_t>()); break;
            case Json::value_t::number_float: {
                const double v = j.get<double>();
                if (std::isfinite(v)) {
                    appendNumber(m_out, v);
                } else {
                    m_out += "null";
                }
                break;
            }
            default: m_out += "null"; break;  // null (binary and discarded are never built)
        }
    }

private:
    void newline(size_t depth) {
        if (m_compact) return;
        m_out += '\n';
        m_out.append(2 * depth, ' ');
    }

    void writeObject(const Json& j, size_t depth) {
        m_out += '{';
        bool first = true;
        for (auto it = j.begin(); it != j.end(); ++it) {
            if (!first) m_out += ',';
            first = false;
            newline(depth + 1);
            appendQuoted(m_out, it.key());
            m_out += m_compact ? ":" : ": ";
            write(it.value(), depth + 1);
        }
        if (!j.empty()) newline(depth);
        m_out += '}';
    }

    void writeArray(const Json& j, size_t depth) {
        const bool oneLine =
            m_compact || std::all_of(j.begin(), j.end(), [](const Json& item) { return item.is_number(); });
        m_out += '[';
        bool first = true;
        for (const Json& item : j) {
            if (!first) m_out += oneLine ? ", " : ",";
            first = false;
            if (!oneLine) newline(depth + 1);
            write(item, depth + 1);
        }
        if (!oneLine && !j.empty()) newline(depth);
        m_out += ']';
    }

    std::string& m_out;
    bool m_compact = false;
};

}  // namespace

std::string jsonText(const Json& document, JsonLayout layout) {
    std::string out;
    Writer(out, layout).write(document, 0);
    return out;
}

}  // namespace rthdist::cli
