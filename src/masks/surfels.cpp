// Surfel extraction (surfels.hpp). Corner slice k reads voxel slices k - 1
// and k; corner row j of it the voxel rows j - 1 and j of both. Each corner
// slice writes its own lists and they are joined in order, so the output is
// ascending and deterministic; corner rows whose four voxel rows hold no
// selected voxel are skipped.
#include "masks/surfels.hpp"

#include <algorithm>

#include "core/parallel.hpp"
#include "masks/selected.hpp"
#include "masks/surfel_area.hpp"

namespace rthdist::masks::detail {
namespace {

struct SliceSurfels {
    std::vector<uint64_t> corners;
    std::vector<uint8_t> codes;
    uint64_t selected = 0;
};

template <class T>
void scanCornerSlice(const Selected<T>& sel, std::array<int64_t, 3> dims, int64_t k, SliceSurfels& out) {
    const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    const int64_t cx = nx + 1, cy = ny + 1;
    // rows[b][c]: voxel row (j - 1 + b, k - 1 + c) as 0/1 with one unselected voxel either side.
    std::vector<uint8_t> rows[2][2];
    for (auto& pair : rows)
        for (auto& r : pair) r.assign(size_t(nx + 2), 0);
    for (int64_t j = 0; j < cy; ++j) {
        bool any = false;
        for (int b = 0; b < 2; ++b)
            for (int c = 0; c < 2; ++c) {
                std::vector<uint8_t>& r = rows[b][c];
                const int64_t y = j - 1 + b, z = k - 1 + c;
                const bool inside = y >= 0 && y < ny && z >= 0 && z < nz;
                const int64_t start = inside ? (y + ny * z) * nx : 0;
                const unsigned count = inside ? sel.countRow(start, start + nx) : 0;
                if (b == 1 && c == 1) out.selected += count;
                any = any || count > 0;
                if (count == 0) {
                    std::fill(r.begin(), r.end(), uint8_t(0));
                } else {
                    for (int64_t x = 0; x < nx; ++x) r[size_t(x + 1)] = sel(start + x) ? 1 : 0;
                }
            }
        if (!any) continue;
        for (int64_t i = 0; i < cx; ++i) {
            uint8_t code = 0;
            for (int a = 0; a < 2; ++a)
                for (int b = 0; b < 2; ++b)
                    for (int c = 0; c < 2; ++c)
                        if (rows[b][c][size_t(i + a)]) code |= neighbourBit(a, b, c);
            if (code == 0 || code == 255) continue;
            out.corners.push_back(uint64_t(i + cx * (j + cy * k)));
            out.codes.push_back(code);
        }
    }
}

}  // namespace

Surfels extractSurfels(const Volume& v, LabelSelect select, int threads) {
    const int64_t cz = v.dims[2] + 1;
    std::vector<SliceSurfels> slices(static_cast<size_t>(cz));
    withLabels(v, [&](const auto* labels) {
        const Selected sel(labels, select);
        core::parallelChunks(size_t(cz), 1, threads, [&](size_t kb, size_t ke, int) {
            for (size_t k = kb; k < ke; ++k) scanCornerSlice(sel, v.dims, int64_t(k), slices[k]);
        });
    });
    Surfels s;
    size_t total = 0;
    for (const SliceSurfels& slice : slices) total += slice.corners.size();
    s.corners.reserve(total);
    s.codes.reserve(total);
    for (SliceSurfels& slice : slices) {
        s.selected += slice.selected;
        s.corners.insert(s.corners.end(), slice.corners.begin(), slice.corners.end());
        s.codes.insert(s.codes.end(), slice.codes.begin(), slice.codes.end());
        slice = SliceSurfels();
    }
    return s;
}

}  // namespace rthdist::masks::detail
