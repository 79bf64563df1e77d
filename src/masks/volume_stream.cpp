#include "masks/volume_stream.hpp"

#include <algorithm>
#include <cstring>

#include "masks/label_types.hpp"

namespace rthdist::masks::detail {
namespace {

constexpr size_t kInputBytes = size_t(1) << 17;
constexpr size_t kMostPerCall = size_t(1) << 30;  // within zlib's uInt

}  // namespace

VolumeStream::VolumeStream(VolumeFile& file, const std::string& path) : m_file(file), m_path(path) {}

VolumeStream::~VolumeStream() {
    if (m_zlib) inflateEnd(&m_z);
}

std::optional<Error> VolumeStream::fill() {
    m_in.resize(kInputBytes);
    const Result<size_t> got = m_file.readSome(m_in.data(), m_in.size());
    if (!got) return got.error();
    m_eof = *got < m_in.size();
    m_z.next_in = m_in.data();
    m_z.avail_in = uInt(*got);
    return std::nullopt;
}

std::optional<Error> VolumeStream::open() {
    if (auto e = fill()) return e;
    m_gzip = m_z.avail_in >= 2 && m_in[0] == 0x1f && m_in[1] == 0x8b;
    if (!m_gzip) return std::nullopt;
    // 16 + MAX_WBITS: a gzip header and trailer, the trailer's CRC and size checked.
    unsigned char* const next = m_z.next_in;
    const uInt avail = m_z.avail_in;
    if (inflateInit2(&m_z, 16 + MAX_WBITS) != Z_OK) return badInput(m_path, "cannot initialise zlib");
    m_zlib = true;
    m_z.next_in = next;
    m_z.avail_in = avail;
    return std::nullopt;
}

Error VolumeStream::streamError(const std::string& what, const std::string& why) const {
    return badInput(m_path, what + ": " + why + " at byte offset " + std::to_string(m_offset));
}

std::optional<Error> VolumeStream::nextMember(const std::string& what) {
    // Trailing zero padding is tolerated (as src/io's gunzip does); a
    // non-zero byte after it is refused, one right after the member starts
    // the next member (inflate refuses anything else: "incorrect header check").
    bool padding = false;
    for (;;) {
        while (m_z.avail_in > 0 && *m_z.next_in == 0) {
            ++m_z.next_in;
            --m_z.avail_in;
            ++m_offset;
            padding = true;
        }
        if (m_z.avail_in > 0) break;
        if (m_eof) {
            m_ended = true;
            return std::nullopt;
        }
        if (auto e = fill()) return e;
    }
    if (padding) return streamError(what, "corrupt gzip stream: data after the zero padding");
    if (inflateReset(&m_z) != Z_OK) return badInput(m_path, "cannot reset zlib");
    return std::nullopt;
}

std::optional<Error> VolumeStream::inflateSome(char* out, size_t n, size_t& got, const std::string& what) {
    got = 0;
    while (got < n && !m_ended) {
        if (m_z.avail_in == 0 && !m_eof) {
            if (auto e = fill()) return e;
        }
        m_z.next_out = reinterpret_cast<Bytef*>(out + got);
        m_z.avail_out = uInt(std::min(n - got, kMostPerCall));
        const uInt inBefore = m_z.avail_in;
        const uInt outBefore = m_z.avail_out;
        const int rc = inflate(&m_z, Z_NO_FLUSH);
        m_offset += inBefore - m_z.avail_in;
        got += outBefore - m_z.avail_out;
        if (rc == Z_STREAM_END) {
            if (auto e = nextMember(what)) return e;
        } else if (rc == Z_BUF_ERROR && m_z.avail_in == 0 && m_eof) {
            return streamError(what, "truncated gzip stream (the file ends inside a member or its trailer)");
        } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
            return streamError(what,
                               std::string("corrupt gzip stream: ") + (m_z.msg ? m_z.msg : "corrupt data"));
        }
    }
    return std::nullopt;
}

Result<size_t> VolumeStream::copySome(char* out, size_t n) {
    const size_t buffered = std::min<size_t>(n, m_z.avail_in);
    if (buffered > 0) std::memcpy(out, m_z.next_in, buffered);
    m_z.next_in += buffered;
    m_z.avail_in -= uInt(buffered);
    m_offset += buffered;
    if (buffered == n || m_eof) return buffered;
    const Result<size_t> rest = m_file.readSome(out + buffered, n - buffered);
    if (!rest) return rest.error();
    m_offset += *rest;
    return buffered + *rest;
}

std::optional<Error> VolumeStream::read(void* out, size_t n, const std::string& what) {
    size_t got = 0;
    if (m_gzip) {
        if (auto e = inflateSome(static_cast<char*>(out), n, got, what)) return e;
    } else {
        const Result<size_t> copied = copySome(static_cast<char*>(out), n);
        if (!copied) return copied.error();
        got = *copied;
    }
    if (got != n)
        return badInput(m_path, what + " is truncated (" + std::to_string(got) + " of " + std::to_string(n) +
                                    " bytes; the " + (m_gzip ? "inflated stream" : "file") + " ends early)");
    return std::nullopt;
}

std::optional<Error> VolumeStream::finish(const std::string& at) {
    if (!m_gzip) return std::nullopt;
    char past = 0;
    size_t got = 0;
    if (auto e = inflateSome(&past, 1, got, "the gzip stream after " + at)) return e;
    if (got != 0) return badInput(m_path, "the inflated stream continues after " + at + " (refused unread)");
    return std::nullopt;
}

}  // namespace rthdist::masks::detail
