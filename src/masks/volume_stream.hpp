// A volume file's bytes in order, inflated (zlib, a piece at a time) when
// the file starts with gzip's magic, else as they are (a plain .nii, or a
// .nii.gz that is not compressed), read in exact pieces. A gzip stream is
// read to its verified end: finish() inflates past the last byte the reader
// needs and wants the end of the last member (zlib checks each member's
// CRC-32 and ISIZE there), then nothing but zero padding to the end of the
// file. Concatenated members are legal gzip, as in src/io/gzip_inflate.cpp
// (which inflates whole files into memory; a volume is inflated straight
// into its labels instead, and src/masks does not include src/io).
#pragma once

#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "masks/volume_file.hpp"
#include "rthdist/result.hpp"

namespace rthdist::masks::detail {

class VolumeStream {
public:
    // file: opened, at its first byte; both outlive the stream.
    VolumeStream(VolumeFile& file, const std::string& path);
    VolumeStream(const VolumeStream&) = delete;
    VolumeStream& operator=(const VolumeStream&) = delete;
    ~VolumeStream();

    // Reads the first bytes and decides gzip or plain.
    [[nodiscard]] std::optional<Error> open();
    [[nodiscard]] bool gzip() const { return m_gzip; }

    // Exactly n bytes into out, else kBadInput naming `what` and why
    // (corrupt or truncated gzip stream with its byte offset, the stream or
    // the file ends early).
    [[nodiscard]] std::optional<Error> read(void* out, size_t n, const std::string& what);

    // Gzip: the inflated stream ends here (`at`: what the reader has read,
    // for the message) and the gzip stream is whole. Inflates at most one
    // byte past the end, so that a decompression bomb after the voxels is
    // refused without being inflated. Plain files: bytes after the end are
    // not read.
    [[nodiscard]] std::optional<Error> finish(const std::string& at);

private:
    // Up to n inflated bytes into out (got: how many); fewer only at the end
    // of the gzip stream (m_ended) or with an error naming `what`.
    std::optional<Error> inflateSome(char* out, size_t n, size_t& got, const std::string& what);
    // Plain: up to n bytes, the buffered head first.
    Result<size_t> copySome(char* out, size_t n);
    // More of the file into m_in (m_eof at its end).
    std::optional<Error> fill();
    // After a member's end: zero padding to the end of the file (m_ended),
    // or the next member.
    std::optional<Error> nextMember(const std::string& what);
    // "<path>: <what>: <why> at byte offset <m_offset>".
    Error streamError(const std::string& what, const std::string& why) const;

    VolumeFile& m_file;
    const std::string& m_path;
    std::vector<unsigned char> m_in;
    z_stream m_z{};
    bool m_zlib = false;  // inflateInit2 succeeded
    bool m_gzip = false;
    bool m_eof = false;     // the file has no more bytes for m_in
    bool m_ended = false;   // gzip: the last member ended, zero padding after it
    uint64_t m_offset = 0;  // file offset of m_z.next_in
};

}  // namespace rthdist::masks::detail
