#include "io/gzip_inflate.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "io/io_error.hpp"

namespace rthdist::io {
namespace {

// RAII owner of an inflate stream, so that every early return frees it.
class Inflater {
public:
    Inflater() = default;
    Inflater(const Inflater&) = delete;
    Inflater& operator=(const Inflater&) = delete;
    ~Inflater() {
        if (m_ready) inflateEnd(&m_stream);
    }
    bool init() {
        // 16 + MAX_WBITS: expect a gzip header and trailer (with CRC check).
        m_ready = inflateInit2(&m_stream, 16 + MAX_WBITS) == Z_OK;
        return m_ready;
    }
    z_stream& stream() { return m_stream; }

private:
    z_stream m_stream{};
    bool m_ready = false;
};

// Deflate cannot expand more than ~1032:1; the gzip trailer's size field is
// only a hint (mod 2^32, attacker-controlled), so it is clamped by that bound.
size_t initialCapacity(std::string_view compressed) {
    if (compressed.size() < 18) return 4096;
    const auto* tail = reinterpret_cast<const unsigned char*>(compressed.data() + compressed.size() - 4);
    const uint64_t hinted =
        uint64_t{tail[0]} | uint64_t{tail[1]} << 8 | uint64_t{tail[2]} << 16 | uint64_t{tail[3]} << 24;
    const uint64_t bound = uint64_t{compressed.size()} * 1032;
    return static_cast<size_t>(std::clamp<uint64_t>(hinted, 4096, std::max<uint64_t>(bound, 4096)));
}

}  // namespace

Result<std::string> gunzip(std::string_view compressed, const std::string& path) {
    if (compressed.size() < 2 || static_cast<unsigned char>(compressed[0]) != 0x1f ||
        static_cast<unsigned char>(compressed[1]) != 0x8b) {
        return badInput(path, offsetWhere(0), "not a gzip stream (bad magic)");
    }
    Inflater inflater;
    if (!inflater.init()) return badInput(path, "gzip", "cannot initialise zlib");
    z_stream& zs = inflater.stream();

    std::string out;
    out.resize(initialCapacity(compressed));
    size_t produced = 0;
    size_t consumed = 0;
    constexpr size_t kChunk = std::numeric_limits<uInt>::max() / 2;
    for (;;) {
        if (produced == out.size()) out.resize(out.size() * 2);
        const size_t inLeft = compressed.size() - consumed;
        zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + consumed));
        zs.avail_in = static_cast<uInt>(std::min(inLeft, kChunk));
        zs.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
        zs.avail_out = static_cast<uInt>(std::min(out.size() - produced, kChunk));
        const uInt inBefore = zs.avail_in;
        const uInt outBefore = zs.avail_out;
        const int rc = inflate(&zs, Z_NO_FLUSH);
        consumed += inBefore - zs.avail_in;
        produced += outBefore - zs.avail_out;
        if (rc == Z_STREAM_END) {
            // Concatenated members are legal gzip; trailing zero padding is tolerated.
            const std::string_view rest = compressed.substr(consumed);
            if (rest.find_first_not_of('\0') == std::string_view::npos) break;
            if (inflateReset(&zs) != Z_OK) return badInput(path, "gzip", "cannot reset zlib");
            continue;
        }
        if (rc == Z_OK) continue;
        if (rc == Z_BUF_ERROR && consumed == compressed.size() && zs.avail_out != 0) {
            return badInput(path, offsetWhere(consumed), "truncated gzip stream");
        }
        if (rc == Z_BUF_ERROR) continue;  // needs more output room
        const char* why = zs.msg != nullptr ? zs.msg : "corrupt data";
        return badInput(path, offsetWhere(consumed), std::string("corrupt gzip stream: ") + why);
    }
    out.resize(produced);
    out.shrink_to_fit();
    return out;
}

}  // namespace rthdist::io
