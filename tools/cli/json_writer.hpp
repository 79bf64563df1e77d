// A small streaming JSON writer for the CLI's --json output.
//
// Strings are escaped per RFC 8259: '"', '\\' and every control character
// below U+0020 are escaped, and bytes that are not well-formed UTF-8 (file
// paths on Linux are arbitrary bytes) become U+FFFD, so the output always
// parses. Non-finite numbers are written as null. Doubles use the shortest text
// that reads back to the same value; floats are written as their exact double.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rthdist::cli {

// Returns `text` as a quoted, escaped JSON string.
[[nodiscard]] std::string jsonQuote(std::string_view text);

class JsonWriter {
public:
    // indent 0 writes everything on one line.
    explicit JsonWriter(int indent = 2) : m_indent(indent) {}

    JsonWriter& beginObject();
    JsonWriter& endObject();
    // inlineItems: keep the items on one line (short arrays of numbers).
    JsonWriter& beginArray(bool inlineItems = false);
    JsonWriter& endArray();
    JsonWriter& key(std::string_view name);

    JsonWriter& value(std::string_view text);
    JsonWriter& value(const char* text) { return value(std::string_view(text)); }
    JsonWriter& value(const std::string& text) { return value(std::string_view(text)); }
    JsonWriter& value(bool flag);
    JsonWriter& value(double number);
    JsonWriter& value(float number);
    JsonWriter& value(int64_t number);
    JsonWriter& value(uint64_t number);
    JsonWriter& value(int number) { return value(int64_t(number)); }
    JsonWriter& value(uint32_t number) { return value(uint64_t(number)); }
    JsonWriter& null();

    // key(name).value(v) in one call.
    template <class T>
    JsonWriter& field(std::string_view name, const T& v) {
        key(name);
        return value(v);
    }

    // The document so far; complete once every begin has its end.
    [[nodiscard]] const std::string& str() const { return m_out; }

private:
    struct Frame {
        bool array = false;
        bool inlineItems = false;
        bool empty = true;
    };
    void beforeValue();
    void newline(size_t depth);
    void writeRaw(std::string_view text);

    std::string m_out;
    std::vector<Frame> m_stack;
    int m_indent = 2;
    bool m_afterKey = false;
};

}  // namespace rthdist::cli
