#include "cli/json_writer.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>

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

}  // namespace

std::string jsonQuote(std::string_view text) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(text.size() + 2);
    out += '"';
    for (size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x80) {
            const size_t len = utf8SequenceLength(text, i);
            if (len == 0) {
                out += "\\ufffd";
                ++i;
            } else {
                out.append(text.substr(i, len));
                i += len;
            }
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
    return out;
}

void JsonWriter::newline(size_t depth) {
    if (m_indent <= 0) return;
    m_out += '\n';
    m_out.append(depth * static_cast<size_t>(m_indent), ' ');
}

void JsonWriter::beforeValue() {
    if (m_afterKey) {
        m_afterKey = false;
        return;
    }
    if (m_stack.empty()) {
        if (!m_out.empty()) throw std::logic_error("JsonWriter: a second top-level value");
        return;
    }
    Frame& top = m_stack.back();
    if (!top.array) throw std::logic_error("JsonWriter: object member without a key");
    if (!top.empty) m_out += top.inlineItems ? ", " : ",";
    if (!top.inlineItems) newline(m_stack.size());
    top.empty = false;
}

void JsonWriter::writeRaw(std::string_view text) {
    beforeValue();
    m_out += text;
}

JsonWriter& JsonWriter::beginObject() {
    beforeValue();
    m_out += '{';
    m_stack.push_back({false, false, true});
    return *this;
}

JsonWriter& JsonWriter::endObject() {
    if (m_stack.empty() || m_stack.back().array || m_afterKey) {
        throw std::logic_error("JsonWriter: endObject without an open object");
    }
    const bool empty = m_stack.back().empty;
    m_stack.pop_back();
    if (!empty) newline(m_stack.size());
    m_out += '}';
    return *this;
}

JsonWriter& JsonWriter::beginArray(bool inlineItems) {
    beforeValue();
    m_out += '[';
    m_stack.push_back({true, inlineItems || m_indent <= 0, true});
    return *this;
}

JsonWriter& JsonWriter::endArray() {
    if (m_stack.empty() || !m_stack.back().array) {
        throw std::logic_error("JsonWriter: endArray without an open array");
    }
    const Frame frame = m_stack.back();
    m_stack.pop_back();
    if (!frame.empty && !frame.inlineItems) newline(m_stack.size());
    m_out += ']';
    return *this;
}

JsonWriter& JsonWriter::key(std::string_view name) {
    if (m_stack.empty() || m_stack.back().array || m_afterKey) {
        throw std::logic_error("JsonWriter: key outside an object");
    }
    Frame& top = m_stack.back();
    if (!top.empty) m_out += ',';
    newline(m_stack.size());
    top.empty = false;
    m_out += jsonQuote(name);
    m_out += m_indent > 0 ? ": " : ":";
    m_afterKey = true;
    return *this;
}

JsonWriter& JsonWriter::value(std::string_view text) {
    writeRaw(jsonQuote(text));
    return *this;
}

JsonWriter& JsonWriter::value(bool flag) {
    writeRaw(flag ? "true" : "false");
    return *this;
}

JsonWriter& JsonWriter::value(double number) {
    if (!std::isfinite(number)) return null();
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, number);
    writeRaw(std::string_view(buf, static_cast<size_t>(res.ptr - buf)));
    return *this;
}

// A float is written as the shortest decimal of its exact double value, so a
// reader parsing doubles gets the float32 coordinate exactly (recomputing a
// distance from the written points gives the reported distance).
JsonWriter& JsonWriter::value(float number) { return value(static_cast<double>(number)); }

JsonWriter& JsonWriter::value(int64_t number) {
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, number);
    writeRaw(std::string_view(buf, static_cast<size_t>(res.ptr - buf)));
    return *this;
}

JsonWriter& JsonWriter::value(uint64_t number) {
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, number);
    writeRaw(std::string_view(buf, static_cast<size_t>(res.ptr - buf)));
    return *this;
}

JsonWriter& JsonWriter::null() {
    writeRaw("null");
    return *this;
}

}  // namespace rthdist::cli
