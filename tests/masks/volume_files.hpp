// Volume files written byte by byte for the reader tests (volume_input_test.cpp,
// masks_cli_test.cpp): NIfTI-1 and NIfTI-2 headers with any field set, .npy
// files with any header text, gzip.
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>

namespace rthdist::masks_test {

inline void writeFile(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline void writeGz(const std::string& path, const std::string& bytes) {
    gzFile g = gzopen(path.c_str(), "wb9");
    ASSERT_NE(g, nullptr);
    ASSERT_EQ(gzwrite(g, bytes.data(), unsigned(bytes.size())), int(bytes.size()));
    gzclose(g);
}

template <class T>
inline void put(std::string& b, size_t at, T v) {
    std::memcpy(b.data() + at, &v, sizeof v);
}

// A single-file NIfTI-1 image: header, 4 bytes of extension flag, voxels.
// The fields a test changes are set after.
struct Nifti1 {
    std::string header = std::string(352, '\0');
    std::string voxels;
    Nifti1(int16_t nx, int16_t ny, int16_t nz, int16_t datatype, int bytesPerVoxel) {
        put<int32_t>(header, 0, 348);
        const int16_t dim[8] = {3, nx, ny, nz, 1, 1, 1, 1};
        for (int d = 0; d < 8; ++d) put<int16_t>(header, 40 + 2 * size_t(d), dim[d]);
        put<int16_t>(header, 70, datatype);
        put<int16_t>(header, 72, int16_t(8 * bytesPerVoxel));
        const float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
        for (int d = 0; d < 8; ++d) put<float>(header, 76 + 4 * size_t(d), pixdim[d]);
        put<float>(header, 108, 352.0f);
        std::memcpy(header.data() + 344, "n+1\0", 4);
        voxels.assign(size_t(nx) * size_t(ny) * size_t(nz) * size_t(bytesPerVoxel), '\0');
        voxels[0] = 1;
    }
    void dim(int d, int16_t v) { put<int16_t>(header, 40 + 2 * size_t(d), v); }
    void pixdim(int d, float v) { put<float>(header, 76 + 4 * size_t(d), v); }
    void sform(const float rows[12]) {
        put<int16_t>(header, 254, 1);
        for (int i = 0; i < 12; ++i) put<float>(header, 280 + 4 * size_t(i), rows[i]);
    }
    std::string bytes() const { return header + voxels; }
};

// A single-file NIfTI-2 image of uint8 (the 608-byte shape of the crash).
inline std::string nifti2(int64_t dim0, int64_t nx, int64_t ny, int64_t nz) {
    std::string h(544, '\0');
    put<int32_t>(h, 0, 540);
    std::memcpy(h.data() + 4, "n+2\0\r\n\032\n", 8);
    put<int16_t>(h, 12, 2);
    put<int16_t>(h, 14, 8);
    const int64_t dim[8] = {dim0, nx, ny, nz, 1, 1, 1, 1};
    for (int d = 0; d < 8; ++d) put<int64_t>(h, 16 + 8 * size_t(d), dim[d]);
    for (int d = 0; d < 8; ++d) put<double>(h, 104 + 8 * size_t(d), 1.0);
    put<int64_t>(h, 168, 544);
    return h + std::string(size_t(nx * ny * nz), '\1');
}

inline std::string npy(const std::string& dict, const std::string& data, int major = 1) {
    std::string header = dict;
    const size_t pre = major == 1 ? 10 : 12;
    while ((pre + header.size() + 1) % 64 != 0) header += ' ';
    header += '\n';
    std::string out = std::string("\x93NUMPY", 6) + char(major) + '\0';
    const uint32_t len = uint32_t(header.size());
    out += char(len & 0xff);
    out += char((len >> 8) & 0xff);
    if (major != 1) {
        out += char((len >> 16) & 0xff);
        out += char(len >> 24);
    }
    return out + header + data;
}

}  // namespace rthdist::masks_test
