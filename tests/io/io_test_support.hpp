// Fixtures for the loader tests: a per-test temp directory, byte builders
// for binary formats, gzip, and the bad-input assertion every error test uses.
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>
#include <glm/common.hpp>

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "rthdist/io.hpp"

namespace rthdist::io::test {

class TempDirTest : public ::testing::Test {
public:
    void SetUp() override {
        std::string tmpl = (std::filesystem::temp_directory_path() / "rthdist_io_XXXXXX").string();
        ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
        m_dir = tmpl;
    }
    void TearDown() override {
        std::error_code ec;
        std::filesystem::remove_all(m_dir, ec);
    }

    std::string file(const std::string& name) const { return (m_dir / name).string(); }

    // Writes bytes to name inside the temp dir and returns the full path.
    std::string write(const std::string& name, const std::string& bytes) const {
        const std::string path = file(name);
        std::ofstream out(path, std::ios::binary);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        return path;
    }

private:
    std::filesystem::path m_dir;
};

// Appends fixed-size values in a chosen byte order.
class ByteBuilder {
public:
    explicit ByteBuilder(bool bigEndian = false) : m_bigEndian(bigEndian) {}
    template <class T>
    ByteBuilder& put(T value) {
        unsigned char b[sizeof(T)];
        std::memcpy(b, &value, sizeof(T));
        if (m_bigEndian != (std::endian::native == std::endian::big)) {
            for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
        }
        m_bytes.append(reinterpret_cast<const char*>(b), sizeof(T));
        return *this;
    }
    ByteBuilder& text(const std::string& s) {
        m_bytes += s;
        return *this;
    }
    const std::string& str() const { return m_bytes; }

private:
    bool m_bigEndian;
    std::string m_bytes;
};

inline std::string gzip(const std::string& raw) {
    z_stream zs{};
    EXPECT_EQ(deflateInit2(&zs, Z_BEST_SPEED, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&zs, static_cast<uLong>(raw.size())) + 64, '\0');
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
    zs.avail_in = static_cast<uInt>(raw.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = static_cast<uInt>(out.size());
    EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    return out;
}

// The failure is kBadInput and its message names the file and the place.
template <class T>
::testing::AssertionResult isBadInput(const Result<T>& r, const std::string& path, const std::string& where) {
    if (r.ok()) return ::testing::AssertionFailure() << "expected an error, got a value";
    if (r.error().code != ErrorCode::kBadInput) {
        return ::testing::AssertionFailure() << "code is not kBadInput: " << r.error().message;
    }
    const std::string& msg = r.error().message;
    if (msg.rfind(path + ": ", 0) != 0)
        return ::testing::AssertionFailure() << "message lacks the path prefix: " << msg;
    if (msg.find(where) == std::string::npos) {
        return ::testing::AssertionFailure() << "message lacks '" << where << "': " << msg;
    }
    return ::testing::AssertionSuccess() << msg;
}

// For glTF fixtures: data URIs and the .glb container.
inline std::string base64(const std::string& in) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t v =
            uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
        for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
    }
    if (i + 1 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16;
        out += std::string{kAlphabet[(v >> 18) & 63], kAlphabet[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
        out +=
            std::string{kAlphabet[(v >> 18) & 63], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], '='};
    }
    return out;
}

inline std::string glb(const std::string& json, const std::string& bin) {
    std::string j = json;
    while (j.size() % 4 != 0) j += ' ';
    std::string b = bin;
    while (b.size() % 4 != 0) b += '\0';
    ByteBuilder out;
    out.text("glTF").put<uint32_t>(2).put<uint32_t>(static_cast<uint32_t>(12 + 8 + j.size() + 8 + b.size()));
    out.put<uint32_t>(static_cast<uint32_t>(j.size())).put<uint32_t>(0x4E4F534A).text(j);
    out.put<uint32_t>(static_cast<uint32_t>(b.size())).put<uint32_t>(0x004E4942).text(b);
    return out.str();
}

inline std::vector<glm::vec3> threePoints() {
    return {{1.5f, -2.25f, 3.0f}, {0.0f, 1e-3f, -7.5f}, {100.0f, 200.5f, -300.25f}};
}

}  // namespace rthdist::io::test
