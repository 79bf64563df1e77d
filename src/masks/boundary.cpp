// Boundary extraction: see boundary.hpp for the definition. Work is split by
// z-slice; each slice writes its own index list and the lists are joined in
// slice order, so the output is ascending and deterministic. Rows without a
// selected voxel are skipped after a branch-free count.
#include "masks/boundary.hpp"

#include <algorithm>
#include <cstdlib>

#include "core/parallel.hpp"
#include "masks/selected.hpp"
#include "masks/slice_lists.hpp"

namespace rthdist::masks::detail {
namespace {

template <class T>
Extraction extractFrom(const T* labels, Dims dims, LabelSelect select, int connectivity, int threads) {
    const Selected<T> sel(labels, select);
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
    std::vector<uint64_t> counts(size_t(std::max<int64_t>(nz, 0)), 0);
    Extraction e;
    e.boundary = perSlice(nz, threads, [&](int64_t z, std::vector<uint64_t>& out) {
        uint64_t count = 0;
        for (int64_t y = 0; y < ny; ++y) {
            const int64_t row = y * sy + z * sz;
            const unsigned inRow = sel.countRow(row, row + nx);
            if (inRow == 0) continue;
            count += inRow;
            const bool edgeRow = y == 0 || y == ny - 1 || z == 0 || z == nz - 1;
            for (int64_t x = 0; x < nx; ++x) {
                const int64_t at = row + x;
                if (!sel(at)) continue;
                bool boundary = edgeRow || x == 0 || x == nx - 1;
                if (!boundary) {
                    for (int64_t o : offsets) {
                        if (!sel(at + o)) {
                            boundary = true;
                            break;
                        }
                    }
                }
                if (boundary) out.push_back(uint64_t(at));
            }
        }
        counts[size_t(z)] = count;
    });
    for (uint64_t c : counts) e.count += c;
    return e;
}

template <class A, class B>
std::vector<uint64_t> differenceFrom(const A* a, LabelSelect sa, const B* b, LabelSelect sb, Dims dims,
                                     int threads) {
    const Selected<A> inA(a, sa);
    const Selected<B> inB(b, sb);
    const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    return perSlice(nz, threads, [&](int64_t z, std::vector<uint64_t>& out) {
        for (int64_t y = 0; y < ny; ++y) {
            const int64_t row = (y + ny * z) * nx;
            if (inA.countRow(row, row + nx) == 0) continue;
            for (int64_t x = row; x < row + nx; ++x)
                if (inA(x) && !inB(x)) out.push_back(uint64_t(x));
        }
    });
}

template <class A, class B>
std::optional<uint64_t> firstCommonFrom(const A* a, LabelSelect sa, const B* b, LabelSelect sb, size_t n) {
    const Selected<A> inA(a, sa);
    const Selected<B> inB(b, sb);
    for (size_t i = 0; i < n; ++i)
        if (inA(int64_t(i)) && inB(int64_t(i))) return i;
    return std::nullopt;
}

// Calls fn(labelsA, labelsB) with the stored arrays' typed pointers.
template <class Fn>
auto withLabels(const Volume& a, const Volume& b, Fn&& fn) {
    if (!a.labels8.empty()) {
        if (!b.labels8.empty()) return fn(a.labels8.data(), b.labels8.data());
        return fn(a.labels8.data(), b.labels.data());
    }
    if (!b.labels8.empty()) return fn(a.labels.data(), b.labels8.data());
    return fn(a.labels.data(), b.labels.data());
}

}  // namespace

Extraction extractBoundary(const Volume& v, LabelSelect select, int connectivity, int threads) {
    if (!v.labels8.empty()) return extractFrom(v.labels8.data(), v.dims, select, connectivity, threads);
    return extractFrom(v.labels.data(), v.dims, select, connectivity, threads);
}

std::vector<uint64_t> differenceVoxels(const Volume& a, LabelSelect sa, const Volume& b, LabelSelect sb,
                                       int threads) {
    return withLabels(a, b, [&](const auto* la, const auto* lb) {
        return differenceFrom(la, sa, lb, sb, a.dims, threads);
    });
}

std::optional<uint64_t> firstCommonVoxel(const Volume& a, LabelSelect sa, const Volume& b, LabelSelect sb) {
    return withLabels(a, b, [&](const auto* la, const auto* lb) {
        return firstCommonFrom(la, sa, lb, sb, a.storedVoxels());
    });
}

}  // namespace rthdist::masks::detail
