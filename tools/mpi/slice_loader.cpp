#include "slice_loader.hpp"

#include <cstring>
#include <utility>
#include <vector>

namespace rthdist::cli {

namespace {

template <class T>
io::PointArray<T> sliceOf(io::PointArray<T>& all, int rank, int size) {
    const uint64_t n = all.size();
    const uint64_t begin = n * uint64_t(rank) / uint64_t(size), end = n * uint64_t(rank + 1) / uint64_t(size);
    io::PointArray<T> part(all.begin() + std::ptrdiff_t(begin), all.begin() + std::ptrdiff_t(end));
    io::PointArray<T>().swap(all);
    return part;
}

// One 64-bit word into the digest: multiply-xorshift mixing, so that
// reordered, swapped or changed words give another digest (not a defence
// against a chosen collision: it catches accidents).
uint64_t mixWord(uint64_t h, uint64_t w) {
    h ^= w + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdull;
    return h ^ (h >> 33);
}

template <class T>
uint64_t digest(const io::PointArray<T>& points, uint64_t h) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(points.data());
    const size_t n = points.size() * sizeof(T);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w;
        std::memcpy(&w, bytes + i, 8);
        h = mixWord(h, w);
    }
    uint64_t tail = 0;
    std::memcpy(&tail, bytes + i, n - i);
    return mixWord(mixWord(h, tail), n);
}

}  // namespace

uint64_t pointsChecksum(const io::PointCloud& cloud) {
    const uint64_t seed = cloud.scalar == Scalar::kFloat64 ? 64 : 32;
    return cloud.scalar == Scalar::kFloat64 ? digest(cloud.doubles, seed) : digest(cloud.floats, seed);
}

Result<LoadedSlice> loadSlice(const std::string& path, const io::LoadOptions& options, int rank, int size) {
    Result<io::PointCloud> cloud = io::loadPointCloud(path, options);
    if (!cloud) {
        Error e = cloud.error();
        if (e.message.find(path) == std::string::npos) e.message = path + ": " + e.message;
        return e;
    }
    if (cloud->size() == 0) return Error{ErrorCode::kBadInput, path + ": no points"};
    LoadedSlice out;
    out.fileCount = cloud->size();
    out.checksum = pointsChecksum(*cloud);
    out.points.scalar = cloud->scalar;
    if (cloud->scalar == Scalar::kFloat64) {
        out.points.doubles = sliceOf(cloud->doubles, rank, size);
    } else {
        out.points.floats = sliceOf(cloud->floats, rank, size);
    }
    return out;
}

}  // namespace rthdist::cli
