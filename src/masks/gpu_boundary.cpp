// Boundary extraction on the device (gpu_boundary.hpp).
#include "masks/gpu_boundary.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <vector>

#include "core/parallel.hpp"
#include "masks/selected.hpp"
#include "masks_gpu/boundary_pass.hpp"

namespace rthdist::masks::detail {
namespace {

// Rows [y0, y1] x slices [z0, z1] hold every selected voxel (count of them).
struct RowBox {
    uint64_t count = 0;
    int64_t y0 = std::numeric_limits<int64_t>::max(), y1 = -1;
    int64_t z0 = std::numeric_limits<int64_t>::max(), z1 = -1;

    void add(const RowBox& o) {
        count += o.count;
        y0 = std::min(y0, o.y0);
        y1 = std::max(y1, o.y1);
        z0 = std::min(z0, o.z0);
        z1 = std::max(z1, o.z1);
    }
};

template <class T>
RowBox findRows(const T* labels, Dims dims, LabelSelect select, int threads) {
    const Selected<T> sel(labels, select);
    const int64_t nx = dims[0], ny = dims[1];
    std::vector<RowBox> slices(static_cast<size_t>(dims[2]));
    core::parallelChunks(size_t(dims[2]), 1, threads, [&](size_t zb, size_t ze, int) {
        for (size_t z = zb; z < ze; ++z) {
            RowBox& s = slices[z];
            for (int64_t y = 0; y < ny; ++y) {
                const int64_t row = (int64_t(z) * ny + y) * nx;
                const unsigned c = sel.countRow(row, row + nx);
                if (c == 0) continue;
                s.count += c;
                s.y0 = std::min(s.y0, y);
                s.y1 = y;
                s.z0 = s.z1 = int64_t(z);
            }
        }
    });
    RowBox box;
    for (const RowBox& s : slices) box.add(s);
    return box;
}

// The box's rows into the staging memory, slice by slice.
void stageRows(const uint8_t* labels, size_t voxelBytes, Dims dims, const RowBox& rows,
               std::span<uint8_t> staging, int threads) {
    const size_t rowBytes = size_t(dims[0]) * voxelBytes;
    const size_t sliceBytes = size_t(rows.y1 - rows.y0 + 1) * rowBytes;
    const size_t slices = size_t(rows.z1 - rows.z0 + 1);
    core::parallelChunks(slices, 1, threads, [&](size_t b, size_t e, int) {
        for (size_t s = b; s < e; ++s) {
            const size_t from = (size_t(rows.z0 + int64_t(s)) * size_t(dims[1]) + size_t(rows.y0)) * rowBytes;
            std::memcpy(staging.data() + s * sliceBytes, labels + from, sliceBytes);
        }
    });
}

// Linear volume indices of the set bits, ascending (box order is volume order).
core::UninitVector<uint64_t> decodeBits(std::span<const uint32_t> bits, Dims dims, const RowBox& rows,
                                        int threads) {
    const uint64_t nx = uint64_t(dims[0]), sliceVoxels = nx * uint64_t(rows.y1 - rows.y0 + 1);
    const size_t slices = size_t(rows.z1 - rows.z0 + 1);
    std::vector<std::vector<uint64_t>> out(slices);
    core::parallelChunks(slices, 1, threads, [&](size_t b, size_t e, int) {
        for (size_t s = b; s < e; ++s) {
            const uint64_t first = s * sliceVoxels, end = first + sliceVoxels;
            const uint64_t base = (uint64_t(rows.z0) + s) * nx * uint64_t(dims[1]) + uint64_t(rows.y0) * nx;
            for (uint64_t w = first / 32; w * 32 < end; ++w) {
                uint32_t word = bits[size_t(w)];
                while (word != 0) {
                    const uint64_t i = w * 32 + uint64_t(std::countr_zero(word));
                    word &= word - 1;
                    if (i >= first && i < end) out[s].push_back(base + (i - first));
                }
            }
        }
    });
    return core::concatenateParts<core::UninitVector<uint64_t>>(out);
}

}  // namespace

namespace {

// The pass's box of `rows` in volume `v`.
masks_gpu::LabelBox boxOf(const Volume& v, const RowBox& rows, LabelSelect select, int connectivity) {
    masks_gpu::LabelBox box;
    box.nx = uint32_t(v.dims[0]);
    box.ny = uint32_t(rows.y1 - rows.y0 + 1);
    box.nz = uint32_t(rows.z1 - rows.z0 + 1);
    box.eightBit = !v.labels8.empty();
    box.value = select.value;
    box.anyNonZero = select.anyNonZero;
    box.connectivity = connectivity;
    return box;
}

const uint8_t* labelBytes(const Volume& v) {
    return v.labels8.empty() ? reinterpret_cast<const uint8_t*>(v.labels.data()) : v.labels8.data();
}

}  // namespace

Result<std::vector<Extraction>> extractBoundariesOnDevice(masks_gpu::BoundaryPass& pass,
                                                          std::span<const MaskRef> masks, int connectivity,
                                                          int threads) {
    std::vector<Extraction> out(masks.size());
    std::vector<RowBox> rows(masks.size());
    std::vector<size_t> marked;  // masks with a selected voxel, in box order
    std::vector<masks_gpu::LabelBox> boxes;
    for (size_t k = 0; k < masks.size(); ++k) {
        const Volume& v = *masks[k].volume;
        rows[k] = withLabels(
            v, [&](const auto* labels) { return findRows(labels, v.dims, masks[k].select, threads); });
        out[k].count = rows[k].count;
        if (rows[k].count == 0) continue;
        if (v.dims[0] > int64_t(std::numeric_limits<uint32_t>::max()))
            return Error{ErrorCode::kOutOfMemory,
                         "masks: rows longer than 2^32 - 1 voxels for the GPU boundary pass"};
        marked.push_back(k);
        boxes.push_back(boxOf(v, rows[k], masks[k].select, connectivity));
    }
    if (boxes.empty()) return out;
    Result<std::vector<std::span<uint8_t>>> staging = pass.stagingFor(boxes);
    if (!staging) return staging.error();
    for (size_t b = 0; b < boxes.size(); ++b) {
        const Volume& v = *masks[marked[b]].volume;
        stageRows(labelBytes(v), boxes[b].eightBit ? 1 : sizeof(int32_t), v.dims, rows[marked[b]],
                  (*staging)[b], threads);
    }
    Result<std::vector<std::span<const uint32_t>>> bits = pass.mark(boxes);
    if (!bits) return bits.error();
    for (size_t b = 0; b < boxes.size(); ++b)
        out[marked[b]].boundary =
            decodeBits((*bits)[b], masks[marked[b]].volume->dims, rows[marked[b]], threads);
    return out;
}

Result<Extraction> extractBoundaryOnDevice(masks_gpu::BoundaryPass& pass, const Volume& v, LabelSelect select,
                                           int connectivity, int threads) {
    const MaskRef mask{&v, select};
    Result<std::vector<Extraction>> e =
        extractBoundariesOnDevice(pass, std::span(&mask, 1), connectivity, threads);
    if (!e) return e.error();
    return std::move(e->front());
}

Result<std::vector<Extraction>> extractBoundaries(masks_gpu::BoundaryPass* pass,
                                                  std::span<const MaskRef> masks, int connectivity,
                                                  int threads, std::string& where) {
    if (pass != nullptr) {
        Result<std::vector<Extraction>> e = extractBoundariesOnDevice(*pass, masks, connectivity, threads);
        if (e) {
            where = "device";
            return e;
        }
        if (e.error().code != ErrorCode::kOutOfMemory) return e.error();
    }
    std::vector<Extraction> out;
    for (const MaskRef& m : masks) out.push_back(extractBoundary(*m.volume, m.select, connectivity, threads));
    return out;
}

}  // namespace rthdist::masks::detail
