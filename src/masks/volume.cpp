// Label volumes: NumPy .npy read here (format 1.0-3.0: magic, version,
// little-endian header length, a Python dict literal, then the raw array),
// label arrays in memory, grid comparison. NIfTI: nifti.cpp.
#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <string_view>

#include "core/parallel.hpp"
#include "masks/label_types.hpp"
#include "masks/masks.hpp"

namespace rthdist::masks {

using detail::badInput;
using detail::LabelType;

glm::dvec3 Volume::spacing() const {
    return {glm::length(glm::dvec3(voxelToWorld[0])), glm::length(glm::dvec3(voxelToWorld[1])),
            glm::length(glm::dvec3(voxelToWorld[2]))};
}

namespace {

// The value text of `key` in the .npy header dict ("'descr': '<u1', ...").
std::optional<std::string> dictValue(const std::string& header, const std::string& key) {
    const size_t k = header.find("'" + key + "'");
    if (k == std::string::npos) return std::nullopt;
    size_t at = header.find(':', k);
    if (at == std::string::npos) return std::nullopt;
    ++at;
    while (at < header.size() && header[at] == ' ') ++at;
    size_t end = at;
    if (at < header.size() && header[at] == '(') {
        end = header.find(')', at);
        if (end == std::string::npos) return std::nullopt;
        return header.substr(at, end - at + 1);
    }
    if (at < header.size() && header[at] == '\'') {
        end = header.find('\'', at + 1);
        if (end == std::string::npos) return std::nullopt;
        return header.substr(at + 1, end - at - 1);
    }
    while (end < header.size() && header[end] != ',' && header[end] != '}') ++end;
    return header.substr(at, end - at);
}

// The axes of a .npy shape tuple ("(4, 5, 6)").
Result<std::vector<int64_t>> parseShape(const std::string& shape, const std::string& path) {
    std::vector<int64_t> dims;
    const std::string s = shape.substr(1, shape.size() - 2);
    size_t at = 0;
    while (at < s.size()) {
        while (at < s.size() && (s[at] == ' ' || s[at] == ',')) ++at;
        if (at >= s.size()) break;
        size_t end = at;
        while (end < s.size() && std::isdigit(static_cast<unsigned char>(s[end]))) ++end;
        if (end == at) return badInput(path, ".npy shape '" + shape + "' is malformed");
        dims.push_back(std::stoll(s.substr(at, end - at)));
        at = end;
    }
    return dims;
}

// What a .npy header says of its 3-D array.
struct NpyHeader {
    size_t dataAt = 0;  // the array's first byte
    std::string descr;  // dtype, with its byte order ("<u1")
    bool fortran = false;
    std::array<int64_t, 3> dims{0, 0, 0};
};

Result<NpyHeader> parseNpyHeader(const std::vector<char>& bytes, const std::string& path) {
    if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY", 6) != 0)
        return badInput(path, "not a .npy file");
    const int major = uint8_t(bytes[6]);
    size_t headerLen = 0, headerAt = 0;
    if (major == 1) {
        headerLen = uint8_t(bytes[8]) | (size_t(uint8_t(bytes[9])) << 8);
        headerAt = 10;
    } else if (major == 2 || major == 3) {
        if (bytes.size() < 12) return badInput(path, "truncated .npy header");
        for (int i = 0; i < 4; ++i) headerLen |= size_t(uint8_t(bytes[8 + i])) << (8 * i);
        headerAt = 12;
    } else {
        return badInput(path, ".npy format version " + std::to_string(major) + " is not supported");
    }
    if (bytes.size() < headerAt + headerLen) return badInput(path, "truncated .npy header");
    const std::string header(bytes.data() + headerAt, headerLen);
    const auto descr = dictValue(header, "descr");
    const auto order = dictValue(header, "fortran_order");
    const auto shape = dictValue(header, "shape");
    if (!descr || !order || !shape) return badInput(path, ".npy header without descr/fortran_order/shape");
    const Result<std::vector<int64_t>> dims = parseShape(*shape, path);
    if (!dims) return dims.error();
    if (dims->size() != 3)
        return badInput(path, ".npy array has " + std::to_string(dims->size()) + " axes; masks are 3-D");
    return NpyHeader{headerAt + headerLen,
                     *descr,
                     order->find("True") != std::string::npos,
                     {(*dims)[0], (*dims)[1], (*dims)[2]}};
}

// The label type of a .npy dtype: little-endian, or one byte in any order.
Result<const LabelType*> npyType(const std::string& d, const std::string& path) {
    if (d.size() < 3) return badInput(path, ".npy dtype '" + d + "' is not supported");
    if (d[0] == '>' && d.substr(1) != "u1" && d.substr(1) != "i1" && d.substr(1) != "b1")
        return badInput(path, "big-endian .npy arrays are not supported (dtype '" + d + "')");
    const LabelType* type = detail::labelType(std::string_view(d).substr(1));
    if (type == nullptr) return badInput(path, ".npy dtype '" + d + "' is not a label type");
    return type;
}

// A C-order array ((i, j, k) at (i * n1 + j) * n2 + k) stored i fastest:
// for each j an (i, k) transpose, in square tiles (a tile's rows of both
// arrays stay in cache; the naive loop wrote one cache line per voxel), the
// j planes spread over every hardware thread.
template <class T>
void fromCOrder(const T* in, const std::array<int64_t, 3>& dims, T* out) {
    constexpr int64_t kTile = 64;
    const int64_t n0 = dims[0], n1 = dims[1], n2 = dims[2];
    core::parallelChunks(size_t(n1), 1, 0, [&](size_t jb, size_t je, int) {
        for (int64_t j = int64_t(jb); j < int64_t(je); ++j)
            for (int64_t i0 = 0; i0 < n0; i0 += kTile)
                for (int64_t k0 = 0; k0 < n2; k0 += kTile) {
                    const int64_t i1 = std::min(n0, i0 + kTile), k1 = std::min(n2, k0 + kTile);
                    for (int64_t k = k0; k < k1; ++k) {
                        T* row = out + size_t(n0 * (j + n1 * k));
                        for (int64_t i = i0; i < i1; ++i) row[i] = in[size_t((i * n1 + j) * n2 + k)];
                    }
                }
    });
}

// The labels of a 3-D array at `raw` (C order, or Fortran when `fortran`)
// into v, i fastest: bool and uint8 as bytes (labels8), the other types
// converted to int32.
std::optional<Error> readLabels(const char* raw, const std::array<int64_t, 3>& dims, bool fortran,
                                const LabelType& type, const std::string& path, Volume& v) {
    const uint64_t n = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
    if (type.npyKind == "u1") {
        const uint8_t* b8 = reinterpret_cast<const uint8_t*>(raw);
        v.labels8.resize(n);
        if (fortran) {
            std::copy(b8, b8 + n, v.labels8.begin());
        } else {
            fromCOrder(b8, dims, v.labels8.data());
        }
        return std::nullopt;
    }
    std::vector<int32_t> flat;
    if (auto e = type.toLabels(raw, n, false, 1, 0, path, flat)) return e;
    if (fortran) {
        v.labels = std::move(flat);  // already i fastest
    } else {
        v.labels.resize(n);
        fromCOrder(flat.data(), dims, v.labels.data());
    }
    return std::nullopt;
}

// The .npy file's array (after its header) into v.
std::optional<Error> readNpyLabels(const std::vector<char>& bytes, const NpyHeader& h, const LabelType& type,
                                   const std::string& path, Volume& v) {
    const uint64_t n = uint64_t(h.dims[0]) * uint64_t(h.dims[1]) * uint64_t(h.dims[2]);
    if (bytes.size() - h.dataAt < n * type.bytes)
        return badInput(path, ".npy data is truncated (" + std::to_string(bytes.size() - h.dataAt) +
                                  " bytes for " + std::to_string(n) + " voxels of " +
                                  std::to_string(type.bytes) + " bytes)");
    return readLabels(bytes.data() + h.dataAt, h.dims, h.fortran, type, path, v);
}

}  // namespace

Result<Volume> loadNpy(const std::string& path, glm::dvec3 spacing, const std::optional<glm::dmat4>& affine) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return badInput(path, "cannot open the file");
    const std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const Result<NpyHeader> header = parseNpyHeader(bytes, path);
    if (!header) return header.error();
    const Result<const LabelType*> type = npyType(header->descr, path);
    if (!type) return type.error();
    Volume v;
    v.path = path;
    v.dims = header->dims;
    if (auto e = readNpyLabels(bytes, *header, **type, path, v)) return *e;
    if (affine) {
        v.voxelToWorld = *affine;
        v.transform = "affine";
    } else {
        if (!(spacing.x > 0 && spacing.y > 0 && spacing.z > 0))
            return Error{ErrorCode::kInvalidArgument, path + ": spacing must be positive"};
        v.voxelToWorld = detail::diagonalAffine(spacing);
        v.transform = "spacing";
    }
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
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(voxelToWorld[c][r]))
                return Error{ErrorCode::kInvalidArgument, name + ": the affine has a non-finite entry"};
    if (voxelToWorld[0][3] != 0.0 || voxelToWorld[1][3] != 0.0 || voxelToWorld[2][3] != 0.0 ||
        voxelToWorld[3][3] != 1.0)
        return Error{ErrorCode::kInvalidArgument, name + ": the affine's last row must be 0 0 0 1"};
    if (glm::determinant(glm::dmat3(voxelToWorld)) == 0.0)
        return Error{ErrorCode::kInvalidArgument,
                     name + ": the affine is singular (a voxel axis of length 0)"};
    Volume v;
    v.path = name;
    v.dims = array.dims;
    v.voxelToWorld = voxelToWorld;
    v.transform = transform;
    if (auto e = readLabels(static_cast<const char*>(array.data), array.dims, array.fortran, *type, name, v))
        return *e;
    return v;
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

}  // namespace rthdist::masks
