#include "io/gzip_inflate.hpp"

#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>

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

// Deflate cannot expand more than ~1032:1.
constexpr uint64_t kMaxDeflateRatio = 1032;

// The last member's trailer size field (ISIZE: its inflated size mod 2^32),
// 0 for a stream too short to hold a member. Only a hint: attacker-controlled.
uint64_t trailerSize(std::string_view compressed) {
    if (compressed.size() < 18) return 0;
    const auto* tail = reinterpret_cast<const unsigned char*>(compressed.data() + compressed.size() - 4);
    return uint64_t{tail[0]} | uint64_t{tail[1]} << 8 | uint64_t{tail[2]} << 16 | uint64_t{tail[3]} << 24;
}

// The trailer's hint clamped by deflate's ratio.
size_t initialCapacity(std::string_view compressed) {
    if (compressed.size() < 18) return 4096;
    const uint64_t bound = uint64_t{compressed.size()} * kMaxDeflateRatio;
    return static_cast<size_t>(
        std::clamp<uint64_t>(trailerSize(compressed), 4096, std::max<uint64_t>(bound, 4096)));
}

// The most bytes the output may hold, and whether a format's header set it.
struct OutputLimit {
    uint64_t limit;
    bool fromHeader = false;
};

Error tooLarge(const std::string& path, const OutputLimit& cap) {
    if (cap.fromHeader) {
        return badInput(path, "gzip",
                        "inflates to more than the " + std::to_string(cap.limit) +
                            " bytes its header accounts for (wrong count, or a decompression bomb)");
    }
    return badInput(path, "gzip",
                    "inflates to more than " + std::to_string(cap.limit) + " bytes (over " +
                        std::to_string(kMaxInflateRatio) +
                        " times its compressed size: refused as a decompression bomb)");
}

// limit + 1 without wrapping: the output needs one byte of room past the cap
// to notice a stream that exceeds it.
uint64_t pastCap(uint64_t limit) { return limit == kNoInflatedBound ? limit : limit + 1; }

struct FreeDecompressor {
    void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// The whole stream in one call of libdeflate (2.6x zlib's speed on the
// Dragon's 34 MB of ASCII PLY, 40 against 104 ms), where it applies: one
// member whose trailer's size hint (ISIZE, mod 2^32) is its whole output,
// within `cap`, with nothing but zero padding after it; libdeflate checks
// the CRC and the size. Anything else (several members, an output past 4
// GiB, corrupt or truncated data, a hint past the cap) is left to zlib's
// loop (nullopt), whose errors name the offset; the output is then
// inflated again, only on those inputs.
std::optional<std::string> inflateWhole(std::string_view compressed, uint64_t cap) {
    const uint64_t hint = trailerSize(compressed);
    if (hint == 0 || hint > cap || hint > uint64_t{compressed.size()} * kMaxDeflateRatio) return std::nullopt;
    const std::unique_ptr<libdeflate_decompressor, FreeDecompressor> d(libdeflate_alloc_decompressor());
    if (!d) return std::nullopt;
    std::string out(static_cast<size_t>(hint), '\0');
    size_t consumed = 0, produced = 0;
    const libdeflate_result r = libdeflate_gzip_decompress_ex(d.get(), compressed.data(), compressed.size(),
                                                              out.data(), out.size(), &consumed, &produced);
    if (r != LIBDEFLATE_SUCCESS || produced != out.size()) return std::nullopt;
    if (compressed.substr(consumed).find_first_not_of('\0') != std::string_view::npos) return std::nullopt;
    return out;
}

// The first kInflateHeadBytes of a one-member stream (or all of a shorter
// one: `whole`), for a format's header check before the whole is inflated;
// nullopt where zlib's loop should take the stream (an error, a second
// member).
struct Head {
    std::string bytes;
    bool whole = false;
};
std::optional<Head> inflateHead(std::string_view compressed) {
    Inflater inflater;
    if (!inflater.init()) return std::nullopt;
    z_stream& zs = inflater.stream();
    Head head;
    head.bytes.resize(kInflateHeadBytes);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
    zs.avail_in =
        static_cast<uInt>(std::min<size_t>(compressed.size(), std::numeric_limits<uInt>::max() / 2));
    zs.next_out = reinterpret_cast<Bytef*>(head.bytes.data());
    zs.avail_out = static_cast<uInt>(head.bytes.size());
    int rc = Z_OK;
    while (rc == Z_OK && zs.avail_out != 0) rc = inflate(&zs, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END && !(rc == Z_BUF_ERROR && zs.avail_out == 0)) return std::nullopt;
    head.bytes.resize(head.bytes.size() - zs.avail_out);
    if (rc == Z_STREAM_END) {
        const std::string_view rest = compressed.substr(zs.total_in);
        if (rest.find_first_not_of('\0') != std::string_view::npos) return std::nullopt;
        head.whole = true;
    }
    return head;
}

}  // namespace

uint64_t inflateCap(uint64_t compressedSize) {
    const uint64_t ratio = compressedSize > kNoInflatedBound / kMaxInflateRatio
                               ? kNoInflatedBound
                               : compressedSize * kMaxInflateRatio;
    return std::max(kMinInflateCap, ratio);
}

Result<std::string> gunzip(std::string_view compressed, const std::string& path, InflatedBound bound,
                           std::optional<uint64_t> maxBytes) {
    if (compressed.size() < 2 || static_cast<unsigned char>(compressed[0]) != 0x1f ||
        static_cast<unsigned char>(compressed[1]) != 0x8b) {
        return badInput(path, offsetWhere(0), "not a gzip stream (bad magic)");
    }
    Inflater inflater;
    if (!inflater.init()) return badInput(path, "gzip", "cannot initialise zlib");
    z_stream& zs = inflater.stream();

    OutputLimit cap{maxBytes.value_or(inflateCap(compressed.size()))};
    // The fast path: the header checked on the head zlib's loop would hand
    // it (before the rest is inflated; its bound becomes the cap), then the
    // whole stream at once where inflateWhole applies. A stream it leaves,
    // or whose head zlib could not give, runs through the loop below from
    // the start (a bomb past the header's cap among them: refused there).
    bool fast = true;
    OutputLimit fastCap = cap;
    if (bound != nullptr) {
        const std::optional<Head> head = inflateHead(compressed);
        fast = head.has_value();
        if (head) {
            auto b = bound(head->bytes, head->whole, path);
            if (!b) return b.error();
            if (*b != kNoInflatedBound && *b <= cap.limit - std::min(cap.limit, kInflatedSlack))
                fastCap = OutputLimit{*b + kInflatedSlack, true};
        }
    }
    if (fast) {
        if (std::optional<std::string> whole = inflateWhole(compressed, fastCap.limit))
            return std::move(*whole);
    }
    bool headChecked = bound == nullptr;
    // Inflate only the head until the header has been checked; never
    // allocate past the cap, whatever the trailer's size hint says.
    const uint64_t hint = initialCapacity(compressed);
    auto firstSize = [&] {
        const uint64_t want = headChecked ? hint : std::min<uint64_t>(hint, kInflateHeadBytes);
        return static_cast<size_t>(std::max<uint64_t>(1, std::min(want, pastCap(cap.limit))));
    };
    std::string out;
    out.resize(firstSize());
    size_t produced = 0;
    size_t consumed = 0;
    auto checkHead = [&](bool whole) -> std::optional<Error> {
        headChecked = true;
        auto b = bound(std::string_view(out.data(), produced), whole, path);
        if (!b) return b.error();
        if (*b != kNoInflatedBound && *b <= cap.limit - std::min(cap.limit, kInflatedSlack)) {
            cap = OutputLimit{*b + kInflatedSlack, true};
        }
        if (out.size() < firstSize()) out.resize(firstSize());
        return std::nullopt;
    };
    constexpr size_t kChunk = std::numeric_limits<uInt>::max() / 2;
    for (;;) {
        if (!headChecked && produced >= kInflateHeadBytes) {
            if (auto err = checkHead(false)) return *err;
        }
        if (produced > cap.limit) return tooLarge(path, cap);
        // Output may go up to the head's end (header unchecked) or one byte
        // past the cap (to notice a stream that exceeds it).
        const uint64_t end = headChecked ? pastCap(cap.limit) : kInflateHeadBytes;
        if (produced == out.size()) {
            out.resize(static_cast<size_t>(std::min<uint64_t>(uint64_t{out.size()} * 2, end)));
        }
        const size_t room = static_cast<size_t>(std::min<uint64_t>(out.size(), end)) - produced;
        zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + consumed));
        zs.avail_in = static_cast<uInt>(std::min(compressed.size() - consumed, kChunk));
        zs.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
        zs.avail_out = static_cast<uInt>(std::min(room, kChunk));
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
    if (!headChecked) {
        if (auto err = checkHead(true)) return *err;
    }
    if (produced > cap.limit) return tooLarge(path, cap);
    out.resize(produced);
    out.shrink_to_fit();
    return out;
}

}  // namespace rthdist::io
