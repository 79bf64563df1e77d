// Label volumes: NumPy .npy read here (the header by npy_header.hpp, the
// array in pieces straight into the volume), label arrays in memory, the
// geometry checks, grid comparison. NIfTI: nifti.cpp.
#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <string_view>

#include "core/parallel.hpp"
#include "masks/label_types.hpp"
#include "masks/npy_header.hpp"
#include "masks/volume_file.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {

using detail::badInput;
using detail::LabelScale;
using detail::LabelType;
using detail::VolumeFile;

glm::dvec3 Volume::spacing() const {
    return {glm::length(glm::dvec3(voxelToWorld[0])), glm::length(glm::dvec3(voxelToWorld[1])),
            glm::length(glm::dvec3(voxelToWorld[2]))};
}

namespace {

// Voxels per piece of a file read (and of a C-order array converted): the
// raw piece and its int32 labels are all the reader holds besides the volume.
constexpr uint64_t kPieceVoxels = uint64_t{1} << 22;

// Where the raw scalars come from, in file order: `next(bytes)` points at
// the next `bytes` bytes (a file read into a piece buffer, or an array in
// memory), valid until the next call.
using NextRaw = std::function<Result<const char*>(size_t bytes)>;

// Planes i0..i1 of a C-order array ((i, j, k) at (i * n1 + j) * n2 + k,
// `in` starting at plane i0) into `out`, i fastest: for each j an (i, k)
// transpose, in square tiles (a tile's rows of both arrays stay in cache),
// the j planes spread over every hardware thread.
template <class T>
void planesFromCOrder(const T* in, int64_t i0, int64_t i1, const std::array<int64_t, 3>& dims, T* out) {
    constexpr int64_t kTile = 64;
    const int64_t n0 = dims[0], n1 = dims[1], n2 = dims[2];
    core::parallelChunks(size_t(n1), 1, 0, [&](size_t jb, size_t je, int) {
        for (int64_t j = int64_t(jb); j < int64_t(je); ++j)
            for (int64_t it = i0; it < i1; it += kTile)
                for (int64_t k0 = 0; k0 < n2; k0 += kTile) {
                    const int64_t ie = std::min(i1, it + kTile), k1 = std::min(n2, k0 + kTile);
                    for (int64_t k = k0; k < k1; ++k) {
                        T* row = out + size_t(n0 * (j + n1 * k));
                        for (int64_t i = it; i < ie; ++i) row[i] = in[size_t(((i - i0) * n1 + j) * n2 + k)];
                    }
                }
    });
}

// The labels of a 3-D array of `type` read through `next` (C order, or
// Fortran when `fortran`) into v, i fastest, in pieces: bool and uint8 as
// bytes (labels8) straight into the volume, the other types converted to
// int32 a piece at a time. Nothing but the volume and one piece is held.
std::optional<Error> readLabels(const NextRaw& next, const std::array<int64_t, 3>& dims, bool fortran,
                                const LabelType& type, const LabelScale& how, const std::string& path,
                                Volume& v) {
    const uint64_t n = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
    const bool bytes8 = type.npyKind == "u1" && !how.scale;
    // Fortran order fills the volume front to back: reserved, and grown a
    // piece at a time, so that a stream that ends early (a .nii.gz whose
    // header promises more than it holds) has not touched the whole volume.
    if (bytes8 && fortran) {
        v.labels8.reserve(n);
    } else if (bytes8) {
        v.labels8.resize(n);
    } else if (fortran) {
        v.labels.reserve(n);
    } else {
        v.labels.resize(n);
    }
    std::vector<int32_t> piece;
    // `count` raw scalars (file order, first at file index `first`) as labels at `out`.
    auto convert = [&](const char* raw, uint64_t count, uint64_t first, void* out) -> std::optional<Error> {
        if (bytes8) {
            std::memcpy(out, raw, size_t(count));
            return std::nullopt;
        }
        return type.toLabels(raw, size_t(count), how, path, first, static_cast<int32_t*>(out));
    };
    if (fortran) {  // the file's order is the volume's
        for (uint64_t at = 0; at < n; at += kPieceVoxels) {
            const uint64_t count = std::min(kPieceVoxels, n - at);
            const Result<const char*> raw = next(size_t(count * type.bytes));
            if (!raw) return raw.error();
            if (bytes8) {
                v.labels8.resize(at + count);
            } else {
                v.labels.resize(at + count);
            }
            void* out = bytes8 ? static_cast<void*>(v.labels8.data() + at) : v.labels.data() + at;
            if (auto e = convert(*raw, count, at, out)) return e;
        }
        return std::nullopt;
    }
    const int64_t n0 = dims[0], n1 = dims[1], n2 = dims[2];
    const uint64_t plane = uint64_t(n1) * uint64_t(n2);
    if (plane <= kPieceVoxels) {  // whole i planes a piece, transposed in tiles
        const int64_t planes = int64_t(std::max<uint64_t>(1, kPieceVoxels / plane));
        std::vector<uint8_t> piece8;
        for (int64_t i0 = 0; i0 < n0; i0 += planes) {
            const int64_t i1 = std::min(n0, i0 + planes);
            const uint64_t count = uint64_t(i1 - i0) * plane;
            const Result<const char*> raw = next(size_t(count * type.bytes));
            if (!raw) return raw.error();
            if (bytes8) {
                planesFromCOrder(reinterpret_cast<const uint8_t*>(*raw), i0, i1, dims, v.labels8.data());
            } else {
                piece.resize(count);
                if (auto e = convert(*raw, count, uint64_t(i0) * plane, piece.data())) return e;
                planesFromCOrder(piece.data(), i0, i1, dims, v.labels.data());
            }
        }
        return std::nullopt;
    }
    // Planes larger than a piece: rows of k scattered with stride n0 * n1.
    for (int64_t i = 0; i < n0; ++i) {
        for (uint64_t q = 0; q < plane; q += kPieceVoxels) {
            const uint64_t count = std::min(kPieceVoxels, plane - q);
            const Result<const char*> raw = next(size_t(count * type.bytes));
            if (!raw) return raw.error();
            const int32_t* labels = nullptr;
            if (!bytes8) {
                piece.resize(count);
                if (auto e = convert(*raw, count, uint64_t(i) * plane + q, piece.data())) return e;
                labels = piece.data();
            }
            int64_t j = int64_t(q / uint64_t(n2)), k = int64_t(q % uint64_t(n2));
            for (uint64_t e = 0; e < count; ++e) {
                const size_t at = size_t(i + n0 * (j + n1 * k));
                if (bytes8) {
                    v.labels8[at] = uint8_t((*raw)[e]);
                } else {
                    v.labels[at] = labels[e];
                }
                if (++k == n2) {
                    k = 0;
                    ++j;
                }
            }
        }
    }
    return std::nullopt;
}

// `next` over a file: reads each piece into one buffer.
NextRaw fileReader(VolumeFile& file, std::vector<char>& buffer, const std::string& what) {
    return [&file, &buffer, what](size_t bytes) -> Result<const char*> {
        buffer.resize(bytes);
        if (auto e = file.readExact(buffer.data(), bytes, what)) return *e;
        return static_cast<const char*>(buffer.data());
    };
}

}  // namespace

namespace detail {

std::optional<Error> readVolumeLabels(const std::function<Result<const char*>(size_t)>& next,
                                      const std::array<int64_t, 3>& dims, bool fortran, const LabelType& type,
                                      const LabelScale& how, const std::string& path, Volume& v) {
    return readLabels(next, dims, fortran, type, how, path, v);
}

}  // namespace detail

Result<Volume> loadNpy(const std::string& path, glm::dvec3 spacing, const std::optional<glm::dmat4>& affine,
                       const VolumeLimits& limits) {
    Result<VolumeFile> file = VolumeFile::open(path);
    if (!file) return file.error();
    std::string head(detail::kNpyMaxPreamble, '\0');
    const Result<size_t> got = file->readSome(head.data(), head.size());
    if (!got) return got.error();
    head.resize(*got);
    const Result<uint64_t> end = detail::npyHeaderEnd(head, path);
    if (!end) return end.error();
    if (*end > head.size()) {
        const size_t have = head.size();
        head.resize(size_t(*end));
        const Result<size_t> more = file->readSome(head.data() + have, head.size() - have);
        if (!more) return more.error();
        head.resize(have + *more);
    }
    const Result<detail::NpyHeader> h = detail::parseNpyHeader(head, file->size(), path);
    if (!h) return h.error();
    const size_t held = h->type->npyKind == "u1" ? 1 : 4;
    if (auto e = detail::checkVolumeBytes(path, h->voxels, h->type->bytes, held, "'" + h->descr + "'",
                                          limits.maxVolumeBytes))
        return *e;
    Volume v;
    v.path = path;
    v.dims = h->dims;
    if (affine) {
        v.voxelToWorld = *affine;
        v.transform = "affine";
    } else {
        v.voxelToWorld = detail::diagonalAffine(spacing);
        v.transform = "spacing";
    }
    if (auto e = detail::checkGrid(v.dims, v.voxelToWorld, path, affine ? "the affine" : "the spacing",
                                   ErrorCode::kBadInput))
        return *e;
    std::vector<char> buffer;
    LabelScale how;
    how.swap = h->swap;
    if (auto e =
            readLabels(fileReader(*file, buffer, ".npy data"), h->dims, h->fortran, *h->type, how, path, v))
        return *e;
    return v;
}

Result<Volume> volumeFromArray(const LabelArray& array, const glm::dmat4& voxelToWorld,
                               const std::string& name, const std::string& transform) {
    const LabelType* type = detail::labelType(array.kind);
    if (type == nullptr)
        return badInput(name, "dtype kind '" + std::string(array.kind) + "' is not a label type");
    for (int64_t d : array.dims)
        if (d < 1) return badInput(name, "a label array needs at least one voxel along each axis");
    if (array.data == nullptr) return Error{ErrorCode::kInvalidArgument, name + ": no array data"};
    if (auto e = detail::checkGrid(array.dims, voxelToWorld, name, "the affine", ErrorCode::kInvalidArgument))
        return *e;
    Volume v;
    v.path = name;
    v.dims = array.dims;
    v.voxelToWorld = voxelToWorld;
    v.transform = transform;
    const char* at = static_cast<const char*>(array.data);
    const NextRaw next = [&at](size_t bytes) -> Result<const char*> {
        const char* p = at;
        at += bytes;
        return p;
    };
    if (auto e = readLabels(next, array.dims, array.fortran, *type, LabelScale{}, name, v)) return *e;
    return v;
}

std::optional<Error> checkVolume(const Volume& v) {
    for (int64_t d : v.dims)
        if (d < 1)
            return Error{ErrorCode::kInvalidArgument,
                         v.path + ": a volume needs at least one voxel along each axis"};
    uint64_t n = 1;
    for (int64_t d : v.dims)
        if (__builtin_mul_overflow(n, uint64_t(d), &n))
            return Error{ErrorCode::kInvalidArgument, v.path + ": the voxel count overflows 64 bits"};
    if (v.storedVoxels() != n)
        return Error{ErrorCode::kInvalidArgument, v.path + ": label array size differs from the dimensions"};
    return detail::checkGrid(v.dims, v.voxelToWorld, v.path, "the voxel-to-world affine",
                             ErrorCode::kInvalidArgument);
}

std::optional<Error> checkSameGrid(const Volume& a, const Volume& b) {
    if (a.dims != b.dims) {
        auto text = [](const Volume& v) {
            return std::to_string(v.dims[0]) + "x" + std::to_string(v.dims[1]) + "x" +
                   std::to_string(v.dims[2]);
        };
        return Error{ErrorCode::kBadInput, "the masks are on different grids: " + a.path + " is " + text(a) +
                                               " voxels, " + b.path + " is " + text(b) +
                                               " (nothing is resampled)"};
    }
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 3; ++r) {
            const double x = a.voxelToWorld[c][r], y = b.voxelToWorld[c][r];
            const double tol = std::max(1e-6, 1e-5 * std::max(std::fabs(x), std::fabs(y)));
            if (std::fabs(x - y) > tol) {
                char text[256];
                std::snprintf(text, sizeof text,
                              "affine entry (%d,%d) is %.9g in %s (%s) and %.9g in %s (%s)", r, c, x,
                              a.path.c_str(), a.transform.c_str(), y, b.path.c_str(), b.transform.c_str());
                return Error{ErrorCode::kBadInput, std::string("the masks are on different grids: ") + text +
                                                       " (nothing is resampled)"};
            }
        }
    }
    return std::nullopt;
}

std::vector<int32_t> labelsPresent(const Volume& v) {
    std::vector<uint8_t> small(256, 0);
    std::set<int32_t> other;
    for (uint8_t l : v.labels8) small[l] = 1;
    for (int32_t l : v.labels) {
        if (l > 0 && l < 256)
            small[size_t(l)] = 1;
        else if (l != 0)
            other.insert(l);
    }
    std::vector<int32_t> out;
    for (int32_t l : other)
        if (l < 0) out.push_back(l);
    for (int l = 1; l < 256; ++l)
        if (small[size_t(l)]) out.push_back(l);
    for (int32_t l : other)
        if (l >= 256) out.push_back(l);
    return out;
}

uint64_t nonzeroVoxels(const Volume& v) {
    if (!v.labels8.empty())
        return uint64_t(v.labels8.size()) -
               uint64_t(std::count(v.labels8.begin(), v.labels8.end(), uint8_t(0)));
    return uint64_t(v.labels.size()) - uint64_t(std::count(v.labels.begin(), v.labels.end(), 0));
}

}  // namespace rthdist::masks
