// LAS 1.0-1.4 point records (ASPRS LAS Specification 1.4 - R15): the public
// header block's field offsets are the same in every version up to byte 227;
// 1.3 adds the waveform start (8 bytes, 235), 1.4 the extended VLRs and the
// 64-bit point counts (375).
#include "io/las_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "io/io_error.hpp"
#include "io/non_finite.hpp"
#include "io/scalar_type.hpp"

namespace rthdist::io {
namespace {

// Byte offsets in the public header block.
constexpr size_t kVersionMajorAt = 24;
constexpr size_t kHeaderSizeAt = 94;
constexpr size_t kPointOffsetAt = 96;
constexpr size_t kFormatAt = 104;
constexpr size_t kRecordLengthAt = 105;
constexpr size_t kLegacyCountAt = 107;
constexpr size_t kScaleAt = 131;       // x, y, z doubles
constexpr size_t kOffsetAt = 155;      // x, y, z doubles
constexpr size_t kPointCountAt = 247;  // 1.4: uint64
// Header sizes: 1.0-1.2, 1.3, 1.4.
constexpr size_t kHeaderSize12 = 227;
constexpr size_t kHeaderSize13 = 235;
constexpr size_t kHeaderSize14 = 375;
// LASzip marks a compressed point format by setting bit 7 (and bit 6).
constexpr uint8_t kCompressedFormatBits = 0xC0;
constexpr int kFormatCount = 11;

template <class T>
T read(std::string_view bytes, size_t at) {
    return detail::loadRaw<T>(bytes.data() + at, false);
}

size_t minHeaderSize(int minor) {
    if (minor >= 4) return kHeaderSize14;
    if (minor == 3) return kHeaderSize13;
    return kHeaderSize12;
}

struct LasHeader {
    int minor = 0;
    uint64_t pointOffset = 0;
    int format = 0;
    uint64_t recordLength = 0;
    uint64_t count = 0;
    std::array<double, 3> scale{};
    std::array<double, 3> offset{};
};

// The signature, the minimum size and the version (1.0 to 1.4) into h.minor.
std::optional<Error> checkVersion(std::string_view bytes, const std::string& path, LasHeader& h) {
    if (!bytes.starts_with("LASF")) {
        return badInput(path, offsetWhere(0), "not a LAS file (no 'LASF' signature)");
    }
    if (bytes.size() < kHeaderSize12) {
        return badInput(path, "header",
                        "the file has " + std::to_string(bytes.size()) + " bytes, fewer than the " +
                            std::to_string(kHeaderSize12) + "-byte LAS header (truncated file)");
    }
    const int major = static_cast<uint8_t>(bytes[kVersionMajorAt]);
    h.minor = static_cast<uint8_t>(bytes[kVersionMajorAt + 1]);
    if (major != 1 || h.minor > 4) {
        return badInput(path, offsetWhere(kVersionMajorAt),
                        "unsupported LAS version " + std::to_string(major) + "." + std::to_string(h.minor) +
                            " (1.0 to 1.4 are read)");
    }
    return std::nullopt;
}

// The header size and the offset to point data, each within the file.
std::optional<Error> readPointOffset(std::string_view bytes, const std::string& path, LasHeader& h) {
    const uint64_t headerSize = read<uint16_t>(bytes, kHeaderSizeAt);
    const std::string version = "1." + std::to_string(h.minor);
    if (headerSize < minHeaderSize(h.minor)) {
        return badInput(path, offsetWhere(kHeaderSizeAt),
                        "header size " + std::to_string(headerSize) + " is smaller than LAS " + version +
                            "'s " + std::to_string(minHeaderSize(h.minor)) + " bytes");
    }
    if (headerSize > bytes.size()) {
        return badInput(path, offsetWhere(kHeaderSizeAt),
                        "header size " + std::to_string(headerSize) + " exceeds the file's " +
                            std::to_string(bytes.size()) + " bytes (truncated file)");
    }
    h.pointOffset = read<uint32_t>(bytes, kPointOffsetAt);
    if (h.pointOffset < headerSize || h.pointOffset > bytes.size()) {
        return badInput(path, offsetWhere(kPointOffsetAt),
                        "offset to point data " + std::to_string(h.pointOffset) + " is outside [" +
                            std::to_string(headerSize) + ", " + std::to_string(bytes.size()) +
                            "] (the header's end to the file's end)");
    }
    return std::nullopt;
}

// The point data format (uncompressed, 0 to 10) and its record length.
std::optional<Error> readFormat(std::string_view bytes, const std::string& path, LasHeader& h) {
    const uint8_t format = static_cast<uint8_t>(bytes[kFormatAt]);
    if ((format & kCompressedFormatBits) != 0) return lazError(path, offsetWhere(kFormatAt));
    if (format >= kFormatCount) {
        return badInput(path, offsetWhere(kFormatAt),
                        "unsupported point data format " + std::to_string(format) + " (0 to 10 are read)");
    }
    h.format = format;
    h.recordLength = read<uint16_t>(bytes, kRecordLengthAt);
    if (h.recordLength < kLasMinRecordLength[format]) {
        return badInput(path, offsetWhere(kRecordLengthAt),
                        "point record length " + std::to_string(h.recordLength) + " is shorter than format " +
                            std::to_string(format) + "'s " + std::to_string(kLasMinRecordLength[format]) +
                            " bytes");
    }
    return std::nullopt;
}

// The point count (1.4: the 64-bit count unless 0, which must agree with a
// non-zero legacy count), and the records within the file.
std::optional<Error> readPointCount(std::string_view bytes, const std::string& path, LasHeader& h) {
    const uint64_t legacyCount = read<uint32_t>(bytes, kLegacyCountAt);
    h.count = legacyCount;
    if (h.minor >= 4) {
        const uint64_t count = read<uint64_t>(bytes, kPointCountAt);
        if (count != 0 && legacyCount != 0 && count != legacyCount) {
            return badInput(path, offsetWhere(kLegacyCountAt),
                            "legacy point count " + std::to_string(legacyCount) +
                                " disagrees with the LAS 1.4 point count " + std::to_string(count));
        }
        if (count != 0) h.count = count;
    }
    return checkRecordsFit(path, h.pointOffset, "the header ", h.count, h.recordLength,
                           bytes.size() - h.pointOffset,
                           "follow the offset to point data (truncated file or wrong count)");
}

// X, Y, Z scale factors (finite, non-zero) and offsets (finite).
std::optional<Error> readScaleOffset(std::string_view bytes, const std::string& path, LasHeader& h) {
    for (size_t axis = 0; axis < 3; ++axis) {
        const std::string name(1, "XYZ"[axis]);
        h.scale[axis] = read<double>(bytes, kScaleAt + 8 * axis);
        h.offset[axis] = read<double>(bytes, kOffsetAt + 8 * axis);
        if (h.scale[axis] == 0.0 || !std::isfinite(h.scale[axis])) {
            return badInput(path, offsetWhere(kScaleAt + 8 * axis),
                            name + " scale factor is " + (h.scale[axis] == 0.0 ? "0" : "not finite") +
                                " (coordinates are integer * scale + offset)");
        }
        if (!std::isfinite(h.offset[axis])) {
            return badInput(path, offsetWhere(kOffsetAt + 8 * axis), name + " offset is not finite");
        }
    }
    return std::nullopt;
}

Result<LasHeader> parseHeader(std::string_view bytes, const std::string& path) {
    LasHeader h;
    for (auto step : {&checkVersion, &readPointOffset, &readFormat, &readPointCount, &readScaleOffset}) {
        if (std::optional<Error> e = step(bytes, path, h)) return *e;
    }
    return h;
}

// Classification of the record at p (formats 0-5: low 5 bits of byte 15;
// 6-10: byte 16).
uint8_t classification(const char* p, int format) {
    return format < 6 ? static_cast<uint8_t>(p[15]) & 0x1F : static_cast<uint8_t>(p[16]);
}

std::string classList(const std::vector<int>& classes) {
    std::string s;
    for (size_t i = 0; i < classes.size(); ++i) s += (i == 0 ? "" : ", ") + std::to_string(classes[i]);
    return s;
}

// The point records cut into chunks of perChunk records.
struct PointChunks {
    const char* file = nullptr;
    const LasHeader& h;
    uint64_t perChunk = 1;

    [[nodiscard]] size_t count() const { return chunkCount(h.count, perChunk); }
    [[nodiscard]] uint64_t begin(size_t c) const { return c * perChunk; }
    [[nodiscard]] uint64_t end(size_t c) const { return std::min(h.count, (c + 1) * perChunk); }
    [[nodiscard]] const char* record(uint64_t k) const { return file + h.pointOffset + k * h.recordLength; }
};

// For each chunk, how many points the filter keeps before it; the last entry
// is the total.
std::vector<uint64_t> keptBefore(const PointChunks& chunks, const std::array<bool, 256>& keep,
                                 const ChunkPlan& plan) {
    std::vector<uint64_t> kept(chunks.count() + 1, 0);
    (void)forEachChunk(chunks.count(), plan, [&](size_t c) -> std::optional<Error> {
        uint64_t n = 0;
        for (uint64_t k = chunks.begin(c); k < chunks.end(c); ++k) {
            n += keep[classification(chunks.record(k), chunks.h.format)] ? 1 : 0;
        }
        kept[c + 1] = n;
        return std::nullopt;
    });
    for (size_t c = 0; c < chunks.count(); ++c) kept[c + 1] += kept[c];
    return kept;
}

// The classification values the file holds, ascending.
std::vector<int> classesPresent(const PointChunks& chunks, const ChunkPlan& plan) {
    std::vector<std::array<bool, 256>> present(chunks.count());
    (void)forEachChunk(chunks.count(), plan, [&](size_t c) -> std::optional<Error> {
        for (uint64_t k = chunks.begin(c); k < chunks.end(c); ++k)
            present[c][classification(chunks.record(k), chunks.h.format)] = true;
        return std::nullopt;
    });
    std::vector<int> found;
    for (int v = 0; v < 256; ++v) {
        const auto has = [v](const std::array<bool, 256>& p) { return p[static_cast<size_t>(v)]; };
        if (std::any_of(present.begin(), present.end(), has)) found.push_back(v);
    }
    return found;
}

// The first kept point of chunk c whose coordinate is not finite, as the
// error naming it (the slow path, for a chunk known to have one).
std::optional<Error> firstNonFinitePoint(const PointChunks& chunks, size_t c,
                                         const std::array<bool, 256>& keep, const std::string& path) {
    const LasHeader& h = chunks.h;
    for (uint64_t k = chunks.begin(c); k < chunks.end(c); ++k) {
        const char* p = chunks.record(k);
        if (!keep[classification(p, h.format)]) continue;
        for (size_t axis = 0; axis < 3; ++axis) {
            const int32_t raw = detail::loadRaw<int32_t>(p + 4 * axis, false);
            if (!std::isfinite(static_cast<double>(raw) * h.scale[axis] + h.offset[axis])) {
                return badInput(path,
                                "point " + std::to_string(k) + " (" + offsetWhere(p - chunks.file) + ")",
                                std::string(1, "XYZ"[axis]) + " * scale + offset is not finite");
            }
        }
    }
    return std::nullopt;
}

// Chunk c's kept points, X * scale + offset in double, into out; the first
// point whose coordinate is not finite is the chunk's error.
template <bool kFilter>
std::optional<Error> convertPoints(const PointChunks& chunks, size_t c, const std::array<bool, 256>& keep,
                                   glm::dvec3* out, const std::string& path) {
    const LasHeader& h = chunks.h;
    glm::dvec3* next = out;
    for (uint64_t k = chunks.begin(c); k < chunks.end(c); ++k) {
        const char* p = chunks.record(k);
        if (kFilter && !keep[classification(p, h.format)]) continue;
        glm::dvec3 v;
        for (size_t axis = 0; axis < 3; ++axis) {
            const int32_t raw = detail::loadRaw<int32_t>(p + 4 * axis, false);
            v[static_cast<int>(axis)] = static_cast<double>(raw) * h.scale[axis] + h.offset[axis];
        }
        *next++ = v;
    }
    if (anyNonFinite(out, static_cast<size_t>(next - out))) return firstNonFinitePoint(chunks, c, keep, path);
    return std::nullopt;
}

}  // namespace

Error lazError(const std::string& path, const std::string& where) {
    return badInput(path, where,
                    "compressed LAS (LAZ) is not read (Debian 12 has no LAZ library); decompress it "
                    "first, e.g. 'laszip -i in.laz -o out.las' or 'pdal translate in.laz out.las', "
                    "and pass the .las file");
}

Result<PointCloud> readLas(std::string_view bytes, const std::string& path, const std::vector<int>& classes,
                           const ChunkPlan& plan) {
    auto header = parseHeader(bytes, path);
    if (!header) return header.error();
    const LasHeader& h = *header;

    std::array<bool, 256> keep{};
    keep.fill(classes.empty());
    for (int c : classes) {
        if (c < 0 || c > 255) {
            return badInput(path, "classification", "class " + std::to_string(c) + " is outside 0..255");
        }
        keep[static_cast<size_t>(c)] = true;
    }
    const PointChunks chunks{bytes.data(), h, plan.items(h.recordLength)};
    std::vector<uint64_t> firstKept(chunks.count() + 1);
    for (size_t c = 0; c <= chunks.count(); ++c) firstKept[c] = std::min(h.count, c * chunks.perChunk);
    if (!classes.empty()) {
        firstKept = keptBefore(chunks, keep, plan);
        if (firstKept.back() == 0 && h.count != 0) {
            return badInput(path, "classification",
                            "none of the " + std::to_string(h.count) + " points has class " +
                                classList(classes) + " (the file holds class " +
                                classList(classesPresent(chunks, plan)) + ")");
        }
    }

    PointCloud cloud;
    cloud.scalar = Scalar::kFloat64;
    cloud.doubles.resize(static_cast<size_t>(firstKept.back()));  // unwritten: each chunk writes its points
    auto err = forEachChunk(chunks.count(), plan, [&](size_t c) -> std::optional<Error> {
        glm::dvec3* out = cloud.doubles.data() + firstKept[c];
        return classes.empty() ? convertPoints<false>(chunks, c, keep, out, path)
                               : convertPoints<true>(chunks, c, keep, out, path);
    });
    if (err) return *err;
    return cloud;
}

}  // namespace rthdist::io
