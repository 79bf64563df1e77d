// writePlyPoints: the smallest lossless container for float points, binary
// little-endian PLY with x/y/z only (readable by every PLY tool).
#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "io/io_error.hpp"
#include "rthdist/io.hpp"

namespace rthdist::io {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

Result<bool> writePlyPoints(const std::string& path, const std::vector<glm::vec3>& points) {
    std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "wb"));
    if (!file) return badInput(path, "open", std::strerror(errno));

    const std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment written by rthdist\nelement vertex " +
        std::to_string(points.size()) +
        "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    if (std::fwrite(header.data(), 1, header.size(), file.get()) != header.size())
        return badInput(path, "write", std::strerror(errno));
    // The body in blocks of kBlock points (a bounded buffer at any size).
    constexpr size_t kBlock = size_t(1) << 20;
    std::vector<char> body(std::min(points.size(), kBlock) * 12);
    for (size_t first = 0; first < points.size(); first += kBlock) {
        const size_t count = std::min(kBlock, points.size() - first);
        for (size_t i = 0; i < count; ++i) {
            for (int axis = 0; axis < 3; ++axis) {
                auto bits = std::bit_cast<uint32_t>(points[first + i][axis]);
                if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
                std::memcpy(body.data() + i * 12 + axis * 4, &bits, 4);
            }
        }
        if (std::fwrite(body.data(), 1, count * 12, file.get()) != count * 12)
            return badInput(path, "write", std::strerror(errno));
    }
    if (std::fclose(file.release()) != 0) return badInput(path, "close", std::strerror(errno));
    return true;
}

}  // namespace rthdist::io
