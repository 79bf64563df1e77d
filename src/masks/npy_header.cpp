// The .npy header (npy_header.hpp): the preamble, then the dict literal by a
// small recursive-descent reader of the Python literals NumPy writes there.
#include "masks/npy_header.hpp"

#include <cstring>
#include <limits>
#include <optional>
#include <vector>

namespace rthdist::masks::detail {
namespace {

std::string quoted(std::string_view s) {
    std::string out;
    for (char c : s.substr(0, 40)) {
        if (c >= 0x20 && c < 0x7f) {
            out += c;
        } else {
            char hex[8];
            std::snprintf(hex, sizeof hex, "\\x%02x", unsigned(static_cast<unsigned char>(c)));
            out += hex;
        }
    }
    return "'" + out + (s.size() > 40 ? "...'" : "'");
}

// A Python dict literal of the three keys, read left to right.
class DictReader {
public:
    DictReader(std::string_view text, const std::string& path) : m_text(text), m_path(path) {}

    std::optional<Error> read(NpyHeader& h) {
        while (m_at < m_text.size() && (m_text[m_at] == ' ' || m_text[m_at] == '\t')) ++m_at;
        if (!take('{')) return fail("the header is not a dict literal ('{' expected)");
        bool seen[3] = {false, false, false};
        for (;;) {
            skip();
            if (take('}')) break;
            std::string key;
            if (auto e = string("a key", key)) return e;
            int which = key == "descr" ? 0 : key == "fortran_order" ? 1 : key == "shape" ? 2 : -1;
            if (which < 0)
                return fail("key " + quoted(key) + " is not one of 'descr', 'fortran_order', 'shape'");
            if (seen[which]) return fail("key '" + key + "' appears twice");
            seen[which] = true;
            skip();
            if (!take(':')) return fail("':' expected after key '" + key + "'");
            skip();
            if (which == 0) {
                if (m_at < m_text.size() && m_text[m_at] == '[')
                    return fail("descr: a structured dtype (a list) is not a label type");
                if (auto e = string("descr (a string)", h.descr)) return e;
            } else if (which == 1) {
                if (auto e = boolean(h.fortran)) return e;
            } else {
                if (auto e = shape(h)) return e;
            }
            skip();
            if (take(',')) continue;
            skip();
            if (take('}')) break;
            return fail("',' or '}' expected after the value of '" + key + "'");
        }
        skip();
        if (m_at != m_text.size()) return fail("text after the dict: " + quoted(m_text.substr(m_at)));
        for (int k = 0; k < 3; ++k)
            if (!seen[k])
                return fail(std::string("key '") +
                            (k == 0   ? "descr"
                             : k == 1 ? "fortran_order"
                                      : "shape") +
                            "' is missing");
        return std::nullopt;
    }

private:
    Error fail(const std::string& what) const {
        return badInput(m_path, ".npy header: " + what + " (at header byte " + std::to_string(m_at) + ")");
    }
    void skip() {
        while (m_at < m_text.size() && (m_text[m_at] == ' ' || m_text[m_at] == '\t' || m_text[m_at] == '\n' ||
                                        m_text[m_at] == '\r' || m_text[m_at] == '\f'))
            ++m_at;
    }
    bool take(char c) {
        if (m_at < m_text.size() && m_text[m_at] == c) {
            ++m_at;
            return true;
        }
        return false;
    }
    // A plain '...' or "..." literal: no prefix, no escape, no line break.
    std::optional<Error> string(const char* what, std::string& out) {
        if (m_at >= m_text.size() || (m_text[m_at] != '\'' && m_text[m_at] != '"'))
            return fail(std::string(what) + ": a quoted string expected");
        const char q = m_text[m_at++];
        const size_t start = m_at;
        while (m_at < m_text.size() && m_text[m_at] != q) {
            const char c = m_text[m_at];
            if (c == '\\') return fail(std::string(what) + ": escape sequences are not supported");
            if (c == '\n' || c == '\r' || c == '\0') return fail(std::string(what) + ": unterminated string");
            ++m_at;
        }
        if (m_at >= m_text.size()) return fail(std::string(what) + ": unterminated string");
        out.assign(m_text.substr(start, m_at - start));
        ++m_at;
        if (start == m_at - 1 && m_at < m_text.size() && m_text[m_at] == q)
            return fail(std::string(what) + ": triple-quoted strings are not supported");
        return std::nullopt;
    }
    bool word(std::string_view w) {
        if (m_text.substr(m_at, w.size()) != w) return false;
        const size_t end = m_at + w.size();
        if (end < m_text.size()) {
            const char c = m_text[end];
            if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') return false;
        }
        m_at = end;
        return true;
    }
    std::optional<Error> boolean(bool& out) {
        if (word("True")) {
            out = true;
        } else if (word("False")) {
            out = false;
        } else {
            const size_t end = std::min(m_text.size(), m_at + 12);
            return fail("fortran_order must be True or False, not " +
                        quoted(m_text.substr(m_at, end - m_at)));
        }
        return std::nullopt;
    }
    // A decimal integer literal (digits, '_' between digits; an optional sign).
    std::optional<Error> integer(size_t axis, int64_t& out) {
        const std::string field = "shape[" + std::to_string(axis) + "]";
        bool negative = false;
        if (take('-')) {
            negative = true;
            skip();
        } else if (take('+')) {
            skip();
        }
        const size_t start = m_at;
        if (m_at >= m_text.size() || !std::isdigit(static_cast<unsigned char>(m_text[m_at])))
            return fail(field + ": an integer expected");
        uint64_t v = 0;
        bool overflow = false, lastDigit = false;
        while (m_at < m_text.size()) {
            const char c = m_text[m_at];
            if (std::isdigit(static_cast<unsigned char>(c))) {
                const uint64_t d = uint64_t(c - '0');
                if (v > (uint64_t(std::numeric_limits<int64_t>::max()) - d) / 10) overflow = true;
                v = v * 10 + d;
                lastDigit = true;
            } else if (c == '_' && lastDigit && m_at + 1 < m_text.size() &&
                       std::isdigit(static_cast<unsigned char>(m_text[m_at + 1]))) {
                lastDigit = false;
            } else {
                break;
            }
            ++m_at;
        }
        if (m_at < m_text.size() && (std::isalpha(static_cast<unsigned char>(m_text[m_at])) ||
                                     m_text[m_at] == '_' || m_text[m_at] == '.'))
            return fail(field + ": not a decimal integer");
        if (m_text[start] == '0' && m_at - start > 1) {
            for (size_t i = start; i < m_at; ++i)
                if (m_text[i] != '0' && m_text[i] != '_')
                    return fail(field + ": leading zeros are not a Python integer");
        }
        if (overflow)
            return fail(field + " = " + std::string(m_text.substr(start, m_at - start)) +
                        " exceeds 2^63 - 1");
        if (negative && v != 0) return fail(field + " is negative");
        out = int64_t(v);
        return std::nullopt;
    }
    std::optional<Error> shape(NpyHeader& h) {
        if (!take('(')) return fail("shape must be a tuple '(...)'");
        std::vector<int64_t> dims;
        bool comma = false;
        for (;;) {
            skip();
            if (take(')')) break;
            if (dims.size() >= 32) return fail("shape has more than 32 axes");
            int64_t d = 0;
            if (auto e = integer(dims.size(), d)) return e;
            dims.push_back(d);
            skip();
            comma = take(',');
            if (comma) continue;
            skip();
            if (take(')')) break;
            return fail("shape: ',' or ')' expected");
        }
        if (dims.size() == 1 && !comma) return fail("shape '(n)' is an integer, not a tuple");
        if (dims.size() != 3)
            return fail("shape has " + std::to_string(dims.size()) + " axes; masks are 3-D");
        for (size_t k = 0; k < 3; ++k) {
            if (dims[k] == 0) return fail("shape[" + std::to_string(k) + "] is 0; a mask needs a voxel");
            h.dims[k] = dims[k];
        }
        return std::nullopt;
    }

    std::string_view m_text;
    const std::string& m_path;
    size_t m_at = 0;
};

// descr: an optional byte order and a label kind.
std::optional<Error> setType(NpyHeader& h, const std::string& path) {
    std::string_view d = h.descr;
    char order = '|';
    if (!d.empty() && (d[0] == '<' || d[0] == '>' || d[0] == '|' || d[0] == '=')) {
        order = d[0];
        d.remove_prefix(1);
    }
    if (d == "?") d = "b1";
    h.type = d.size() == 2 ? labelType(d) : nullptr;
    if (h.type == nullptr)
        return badInput(path, ".npy header: descr " + quoted(h.descr) +
                                  " is not a label type (bool, int8..int64, uint8..uint64, float32, "
                                  "float64)");
    h.swap = order == '>' && h.type->bytes > 1;
    return std::nullopt;
}

}  // namespace

Result<uint64_t> npyHeaderEnd(std::string_view head, const std::string& path) {
    if (head.size() < 8 || std::memcmp(head.data(), "\x93NUMPY", 6) != 0)
        return badInput(path, "not a .npy file (magic '\\x93NUMPY' missing)");
    const int major = static_cast<unsigned char>(head[6]), minor = static_cast<unsigned char>(head[7]);
    if (!((major == 1 || major == 2 || major == 3) && minor == 0))
        return badInput(path, ".npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                                  " is not 1.0, 2.0 or 3.0");
    const size_t lengthBytes = major == 1 ? 2 : 4;
    if (head.size() < 8 + lengthBytes)
        return badInput(path, ".npy header length is truncated (the file ends early)");
    uint64_t length = 0;
    for (size_t i = 0; i < lengthBytes; ++i)
        length |= uint64_t(static_cast<unsigned char>(head[8 + i])) << (8 * i);
    if (length > kNpyMaxHeaderBytes)
        return badInput(path, ".npy header length " + std::to_string(length) + " exceeds " +
                                  std::to_string(kNpyMaxHeaderBytes) + " bytes (NumPy's limit)");
    return 8 + lengthBytes + length;
}

Result<NpyHeader> parseNpyHeader(std::string_view bytes, uint64_t fileSize, const std::string& path) {
    const Result<uint64_t> end = npyHeaderEnd(bytes, path);
    if (!end) return end.error();
    if (bytes.size() < *end || fileSize < *end)
        return badInput(path, ".npy header is truncated (the header length says " + std::to_string(*end) +
                                  " bytes, the file has " +
                                  std::to_string(std::min<uint64_t>(bytes.size(), fileSize)) + ")");
    const size_t at = static_cast<unsigned char>(bytes[6]) == 1 ? 10 : 12;
    NpyHeader h;
    h.dataAt = *end;
    if (auto e = DictReader(bytes.substr(at, *end - at), path).read(h)) return *e;
    if (auto e = setType(h, path)) return *e;
    uint64_t n = 1;
    for (int64_t d : h.dims) {
        if (__builtin_mul_overflow(n, uint64_t(d), &n))
            return badInput(path, ".npy header: shape (" + std::to_string(h.dims[0]) + ", " +
                                      std::to_string(h.dims[1]) + ", " + std::to_string(h.dims[2]) +
                                      "): the voxel count overflows 64 bits");
    }
    uint64_t bytesNeeded = 0;
    if (__builtin_mul_overflow(n, uint64_t(h.type->bytes), &bytesNeeded))
        return badInput(path, ".npy header: shape (" + std::to_string(h.dims[0]) + ", " +
                                  std::to_string(h.dims[1]) + ", " + std::to_string(h.dims[2]) + ") of '" +
                                  h.descr + "': the byte count overflows 64 bits");
    if (bytesNeeded > fileSize - h.dataAt)
        return badInput(path, ".npy data is truncated: shape (" + std::to_string(h.dims[0]) + ", " +
                                  std::to_string(h.dims[1]) + ", " + std::to_string(h.dims[2]) + ") of '" +
                                  h.descr + "' needs " + std::to_string(bytesNeeded) +
                                  " bytes, the file has " + std::to_string(fileSize - h.dataAt) +
                                  " after its header");
    h.voxels = n;
    h.dataBytes = bytesNeeded;
    return h;
}

}  // namespace rthdist::masks::detail
