// Boundary extraction: see boundary.hpp for the definition. Work is split in
// slabs of whole z-slices; each slab writes its own index list and the lists
// are joined in slab order, so the output is ascending and deterministic.
#include "masks/boundary.hpp"

#include <algorithm>
#include <cstdlib>

#include "cpu/parallel.hpp"

namespace rthdist::masks::detail {
namespace {

// Per-slab lists joined in order.
std::vector<uint64_t> joinSlabs(std::vector<std::vector<uint64_t>>& slabs) {
    size_t total = 0;
    for (const auto& s : slabs) total += s.size();
    std::vector<uint64_t> out;
    out.reserve(total);
    for (auto& s : slabs) {
        out.insert(out.end(), s.begin(), s.end());
        std::vector<uint64_t>().swap(s);
    }
    return out;
}

constexpr size_t kChunkVoxels = size_t(1) << 20;

}  // namespace

std::vector<uint8_t> selectMask(const Volume& v, LabelSelect select, int threads) {
    std::vector<uint8_t> mask(v.labels.size());
    const int32_t* in = v.labels.data();
    uint8_t* out = mask.data();
    cpu::parallelChunks(mask.size(), kChunkVoxels, threads, [&](size_t b, size_t e, int) {
        if (select.anyNonZero) {
            for (size_t i = b; i < e; ++i) out[i] = in[i] != 0;
        } else {
            for (size_t i = b; i < e; ++i) out[i] = in[i] == select.value;
        }
    });
    return mask;
}

std::vector<uint64_t> boundaryVoxels(const std::vector<uint8_t>& mask, Dims dims, int connectivity,
                                     int threads) {
    const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    const int64_t sy = nx, sz = nx * ny;
    // Neighbour offsets of the connectivity: |dx| + |dy| + |dz| <= 1, 2 or 3.
    const int maxL1 = connectivity == 6 ? 1 : connectivity == 18 ? 2 : 3;
    std::vector<int64_t> offsets;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int l1 = std::abs(dx) + std::abs(dy) + std::abs(dz);
                if (l1 == 0 || l1 > maxL1) continue;
                offsets.push_back(dx + dy * sy + dz * sz);
            }
    std::vector<std::vector<uint64_t>> slabs(size_t(std::max<int64_t>(nz, 0)));
    const uint8_t* m = mask.data();
    cpu::parallelChunks(size_t(nz), 1, threads, [&](size_t zb, size_t ze, int) {
        for (int64_t z = int64_t(zb); z < int64_t(ze); ++z) {
            std::vector<uint64_t>& out = slabs[size_t(z)];
            for (int64_t y = 0; y < ny; ++y) {
                const int64_t row = y * sy + z * sz;
                const bool edgeRow = y == 0 || y == ny - 1 || z == 0 || z == nz - 1;
                for (int64_t x = 0; x < nx; ++x) {
                    const int64_t at = row + x;
                    if (!m[at]) continue;
                    bool boundary = edgeRow || x == 0 || x == nx - 1;
                    if (!boundary) {
                        for (int64_t o : offsets) {
                            if (!m[at + o]) {
                                boundary = true;
                                break;
                            }
                        }
                    }
                    if (boundary) out.push_back(uint64_t(at));
                }
            }
        }
    });
    return joinSlabs(slabs);
}

std::vector<uint64_t> differenceVoxels(const std::vector<uint8_t>& mask, const std::vector<uint8_t>& other,
                                       int threads) {
    const size_t n = mask.size();
    const size_t chunks = (n + kChunkVoxels - 1) / kChunkVoxels;
    std::vector<std::vector<uint64_t>> slabs(chunks);
    cpu::parallelChunks(n, kChunkVoxels, threads, [&](size_t b, size_t e, int) {
        std::vector<uint64_t>& out = slabs[b / kChunkVoxels];
        for (size_t i = b; i < e; ++i)
            if (mask[i] && !other[i]) out.push_back(i);
    });
    return joinSlabs(slabs);
}

uint64_t countVoxels(const std::vector<uint8_t>& mask, int threads) {
    const size_t n = mask.size();
    const size_t chunks = (n + kChunkVoxels - 1) / kChunkVoxels;
    std::vector<uint64_t> counts(chunks, 0);
    cpu::parallelChunks(n, kChunkVoxels, threads, [&](size_t b, size_t e, int) {
        uint64_t c = 0;
        for (size_t i = b; i < e; ++i) c += mask[i] != 0;
        counts[b / kChunkVoxels] = c;
    });
    uint64_t total = 0;
    for (uint64_t c : counts) total += c;
    return total;
}

}  // namespace rthdist::masks::detail
