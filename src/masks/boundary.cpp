// Boundary extraction: see boundary.hpp for the definition. The selection is
// packed into bits once (row_bits.hpp), then each row's boundary is word
// arithmetic on it. Work is split by z-slice; each slice writes its own index
// list and the lists are joined in slice order, so the output is ascending
// and deterministic.
#include "masks/boundary.hpp"

#include <algorithm>
#include <cstdlib>

#include "core/parallel.hpp"
#include "masks/row_bits.hpp"
#include "masks/selected.hpp"
#include "masks/slice_lists.hpp"

namespace rthdist::masks::detail {
namespace {

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
    const RowBits bits(v, select, threads);
    Extraction e;
    e.count = bits.selectedCount();
    if (e.count == 0) return e;
    e.boundary = perSlice<core::UninitVector<uint64_t>>(
        v.dims[2], threads, [&](int64_t z, std::vector<uint64_t>& out) {
            bits.forRowsInUse(z, [&](int64_t y) { bits.appendBoundaryOfRow(y, z, connectivity, out); });
        });
    return e;
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
