// Writes LAS files for the tests (ASPRS LAS 1.4 R15 layout): the public
// header block of version 1.minor, optional variable-length records, then
// point records of one format whose bytes after X/Y/Z are filled with a
// pattern, so a reader that looks at the wrong offset sees garbage.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io_test_support.hpp"

namespace rthdist::io::test {

inline constexpr uint16_t kLasRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

struct LasPoint {
    std::array<int32_t, 3> xyz{};
    uint8_t classification = 1;
    uint8_t classFlags = 0;  // formats 0-5: bits 5-7 of byte 15 (synthetic, key-point, withheld)
};

struct LasSpec {
    int major = 1;
    int minor = 2;
    int format = 0;  // written as is (LASzip's 0x80 bit included)
    uint16_t extraBytes = 0;
    std::array<double, 3> scale{0.01, 0.01, 0.01};
    std::array<double, 3> offset{0.0, 0.0, 0.0};
    std::vector<LasPoint> points;
    int vlrs = 0;  // variable-length records between the header and the points
    // Overrides of what the header says (default: the truth).
    std::optional<uint32_t> legacyCount;
    std::optional<uint64_t> count;  // 1.4
    std::optional<uint16_t> headerSize;
    std::optional<uint32_t> pointOffset;
    std::optional<uint16_t> recordLength;
};

[[nodiscard]] inline uint16_t lasHeaderSize(int minor) { return minor >= 4 ? 375 : minor == 3 ? 235 : 227; }

[[nodiscard]] inline std::string lasBytes(const LasSpec& s) {
    const uint16_t headerSize = lasHeaderSize(s.minor);
    const int baseFormat = s.format & 0x3F;
    const uint16_t recordLength =
        static_cast<uint16_t>((baseFormat <= 10 ? kLasRecordLength[baseFormat] : 20) + s.extraBytes);
    const std::string vlrPayload = "LASF\x01\x02 not points";
    const uint32_t vlrBytes = static_cast<uint32_t>(s.vlrs * (54 + vlrPayload.size()));
    const uint64_t n = s.points.size();
    const bool extended = s.minor >= 4 && baseFormat >= 6;
    ByteBuilder b;
    b.text("LASF").put<uint16_t>(7).put<uint16_t>(0);
    for (int i = 0; i < 16; ++i) b.put<uint8_t>(0);  // project GUID
    b.put<uint8_t>(static_cast<uint8_t>(s.major)).put<uint8_t>(static_cast<uint8_t>(s.minor));
    b.text(std::string(32, 'S')).text(std::string(32, 'G'));
    b.put<uint16_t>(100).put<uint16_t>(2026);
    b.put<uint16_t>(s.headerSize.value_or(headerSize));
    b.put<uint32_t>(s.pointOffset.value_or(headerSize + vlrBytes));
    b.put<uint32_t>(static_cast<uint32_t>(s.vlrs));
    b.put<uint8_t>(static_cast<uint8_t>(s.format)).put<uint16_t>(s.recordLength.value_or(recordLength));
    b.put<uint32_t>(s.legacyCount.value_or(extended ? 0u : static_cast<uint32_t>(n)));
    for (int i = 0; i < 5; ++i) b.put<uint32_t>(0);  // points by return
    for (double v : s.scale) b.put<double>(v);
    for (double v : s.offset) b.put<double>(v);
    for (int i = 0; i < 6; ++i) b.put<double>(0.0);  // max/min x, y, z (not read)
    if (s.minor >= 3) b.put<uint64_t>(0);            // start of waveform data
    if (s.minor >= 4) {
        b.put<uint64_t>(0).put<uint32_t>(0);  // extended VLRs
        b.put<uint64_t>(s.count.value_or(n));
        for (int i = 0; i < 15; ++i) b.put<uint64_t>(0);
    }
    for (int v = 0; v < s.vlrs; ++v) {
        b.put<uint16_t>(0).text(std::string(16, 'U')).put<uint16_t>(42);
        b.put<uint16_t>(static_cast<uint16_t>(vlrPayload.size())).text(std::string(32, 'D')).text(vlrPayload);
    }
    for (const LasPoint& p : s.points) {
        std::string record(recordLength, '\xA5');
        ByteBuilder xyz;
        for (int32_t v : p.xyz) xyz.put<int32_t>(v);
        record.replace(0, 12, xyz.str());
        if (baseFormat < 6) {
            record[15] = static_cast<char>((p.classification & 0x1F) | (p.classFlags & 0xE0));
        } else {
            record[16] = static_cast<char>(p.classification);
        }
        b.text(record);
    }
    return b.str();
}

// What a LAS reader must return for raw X/Y/Z: integer * scale + offset in double.
[[nodiscard]] inline glm::dvec3 lasCoordinates(const LasSpec& s, const LasPoint& p) {
    glm::dvec3 v;
    for (int axis = 0; axis < 3; ++axis) {
        v[axis] = static_cast<double>(p.xyz[static_cast<size_t>(axis)]) * s.scale[static_cast<size_t>(axis)] +
                  s.offset[static_cast<size_t>(axis)];
    }
    return v;
}

}  // namespace rthdist::io::test
