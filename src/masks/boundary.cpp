// Boundary extraction: see boundary.hpp for the definition. Work is split in
// slabs of whole z-slices; each slab writes its own index list and the lists
// are joined in slab order, so the output is ascending and deterministic.
#include "masks/boundary.hpp"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <limits>

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

}  // namespace

namespace {

template <class T>
Selection selectFrom(const T* in, Dims dims, LabelSelect select, int threads) {
    Selection s;
    const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    s.mask.resize(size_t(nx * ny * nz));
    struct Slab {
        uint64_t count = 0;
        Dims lo{INT64_MAX, INT64_MAX, INT64_MAX}, hi{-1, -1, -1};  // hi inclusive here
    };
    std::vector<Slab> slabs(size_t(std::max<int64_t>(nz, 0)));
    uint8_t* out = s.mask.data();
    // A label outside T's range selects nothing (the volume cannot hold it).
    const bool representable =
        select.anyNonZero || (int64_t(select.value) >= int64_t(std::numeric_limits<T>::min()) &&
                              int64_t(select.value) <= int64_t(std::numeric_limits<T>::max()));
    const T value = representable && !select.anyNonZero ? T(select.value) : T(0);
    cpu::parallelChunks(size_t(nz), 1, threads, [&](size_t zb, size_t ze, int) {
        for (int64_t z = int64_t(zb); z < int64_t(ze); ++z) {
            Slab& slab = slabs[size_t(z)];
            for (int64_t y = 0; y < ny; ++y) {
                const size_t row = size_t((y + ny * z) * nx);
                const T* r = in + row;
                uint8_t* o = out + row;
                unsigned rowCount = 0;
                if (!representable) {
                    continue;
                } else if (select.anyNonZero) {
                    for (int64_t x = 0; x < nx; ++x) rowCount += (o[x] = r[x] != 0);
                } else {
                    for (int64_t x = 0; x < nx; ++x) rowCount += (o[x] = r[x] == value);
                }
                if (rowCount == 0) continue;
                slab.count += rowCount;
                int64_t first = 0, last = nx - 1;
                while (!o[first]) ++first;
                while (!o[last]) --last;
                slab.lo = {std::min(slab.lo[0], first), std::min(slab.lo[1], y), std::min(slab.lo[2], z)};
                slab.hi = {std::max(slab.hi[0], last), std::max(slab.hi[1], y), std::max(slab.hi[2], z)};
            }
        }
    });
    Dims lo{INT64_MAX, INT64_MAX, INT64_MAX}, hi{-1, -1, -1};
    for (const Slab& slab : slabs) {
        if (slab.count == 0) continue;
        s.count += slab.count;
        for (int d = 0; d < 3; ++d) {
            lo[d] = std::min(lo[d], slab.lo[d]);
            hi[d] = std::max(hi[d], slab.hi[d]);
        }
    }
    if (s.count > 0) {
        s.lo = lo;
        s.hi = {hi[0] + 1, hi[1] + 1, hi[2] + 1};
    }
    return s;
}

}  // namespace

Selection selectMask(const Volume& v, LabelSelect select, int threads) {
    if (!v.labels8.empty()) return selectFrom(v.labels8.data(), v.dims, select, threads);
    return selectFrom(v.labels.data(), v.dims, select, threads);
}

std::vector<uint64_t> boundaryVoxels(const Selection& s, Dims dims, int connectivity, int threads) {
    if (s.count == 0) return {};
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
    const int64_t z0 = s.lo[2], z1 = s.hi[2];
    std::vector<std::vector<uint64_t>> slabs(size_t(z1 - z0));
    const uint8_t* m = s.mask.data();
    cpu::parallelChunks(size_t(z1 - z0), 1, threads, [&](size_t zb, size_t ze, int) {
        for (int64_t z = z0 + int64_t(zb); z < z0 + int64_t(ze); ++z) {
            std::vector<uint64_t>& out = slabs[size_t(z - z0)];
            for (int64_t y = s.lo[1]; y < s.hi[1]; ++y) {
                const int64_t row = y * sy + z * sz;
                const bool edgeRow = y == 0 || y == ny - 1 || z == 0 || z == nz - 1;
                for (int64_t x = s.lo[0]; x < s.hi[0]; ++x) {
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

std::vector<uint64_t> differenceVoxels(const Selection& s, const Selection& other, Dims dims, int threads) {
    if (s.count == 0) return {};
    const int64_t nx = dims[0], ny = dims[1];
    const int64_t z0 = s.lo[2], z1 = s.hi[2];
    std::vector<std::vector<uint64_t>> slabs(size_t(z1 - z0));
    const uint8_t* m = s.mask.data();
    const uint8_t* o = other.mask.data();
    cpu::parallelChunks(size_t(z1 - z0), 1, threads, [&](size_t zb, size_t ze, int) {
        for (int64_t z = z0 + int64_t(zb); z < z0 + int64_t(ze); ++z) {
            std::vector<uint64_t>& out = slabs[size_t(z - z0)];
            for (int64_t y = s.lo[1]; y < s.hi[1]; ++y) {
                const int64_t row = (y + ny * z) * nx;
                for (int64_t x = s.lo[0]; x < s.hi[0]; ++x)
                    if (m[row + x] && !o[row + x]) out.push_back(uint64_t(row + x));
            }
        }
    });
    return joinSlabs(slabs);
}

}  // namespace rthdist::masks::detail
