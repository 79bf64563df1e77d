// Label volumes: NIfTI-1/2 through libnifti2 (Debian libnifti2-dev), NumPy
// .npy read here (format 1.0-3.0: magic, version, little-endian header
// length, a Python dict literal, then the raw array), grid comparison.
#include <nifti2_io.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string_view>

#include "masks/masks.hpp"

namespace rthdist::masks {
namespace {

Error bad(const std::string& path, const std::string& what) {
    return Error{ErrorCode::kBadInput, path + ": " + what};
}

bool endsWith(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Converts n raw scalars of type T (scaled by slope/inter when `scale`) to
// int32 labels; a non-integral or out-of-range value is an error naming the voxel.
template <class T>
std::optional<Error> toLabels(const void* raw, size_t n, bool scale, double slope, double inter,
                              const std::string& path, std::vector<int32_t>& out) {
    out.resize(n);
    const T* in = static_cast<const T*>(raw);
    for (size_t i = 0; i < n; ++i) {
        T t;
        std::memcpy(&t, in + i, sizeof(T));
        if constexpr (std::is_integral_v<T>) {
            if (!scale) {
                if constexpr (sizeof(T) < 4 || (sizeof(T) == 4 && std::is_signed_v<T>)) {
                    out[i] = int32_t(t);
                    continue;
                } else {
                    if (t <= T(std::numeric_limits<int32_t>::max()) &&
                        (!std::is_signed_v<T> || int64_t(t) >= std::numeric_limits<int32_t>::min())) {
                        out[i] = int32_t(t);
                        continue;
                    }
                    return bad(path, "label " + std::to_string(t) + " at voxel index " + std::to_string(i) +
                                         " does not fit int32");
                }
            }
        }
        double v = double(t);
        if (scale) v = v * slope + inter;
        if (!(std::isfinite(v) && v == std::floor(v) && v >= -2147483648.0 && v <= 2147483647.0)) {
            char text[64];
            std::snprintf(text, sizeof text, "%.17g", v);
            return bad(path, std::string("label value ") + text + " at voxel index " + std::to_string(i) +
                                 " is not an int32 integer (threshold or round probability maps first)");
        }
        out[i] = int32_t(v);
    }
    return std::nullopt;
}

glm::dmat4 fromNifti(const nifti_dmat44& m) {
    glm::dmat4 g(1.0);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) g[c][r] = m.m[r][c];
    return g;
}

struct NiftiFree {
    void operator()(nifti_image* p) const { nifti_image_free(p); }
};

// The scalar types a label array may hold: the NIfTI datatype, the NumPy
// kind (dtype without its byte order; b1 reads as u1) and the conversion.
struct LabelType {
    int niftiType;
    std::string_view npyKind;
    size_t bytes;
    std::optional<Error> (*toLabels)(const void* raw, size_t n, bool scale, double slope, double inter,
                                     const std::string& path, std::vector<int32_t>& out);
};

constexpr LabelType kLabelTypes[] = {
    {DT_UINT8, "u1", 1, &toLabels<uint8_t>},   {DT_INT8, "i1", 1, &toLabels<int8_t>},
    {DT_UINT16, "u2", 2, &toLabels<uint16_t>}, {DT_INT16, "i2", 2, &toLabels<int16_t>},
    {DT_UINT32, "u4", 4, &toLabels<uint32_t>}, {DT_INT32, "i4", 4, &toLabels<int32_t>},
    {DT_UINT64, "u8", 8, &toLabels<uint64_t>}, {DT_INT64, "i8", 8, &toLabels<int64_t>},
    {DT_FLOAT32, "f4", 4, &toLabels<float>},   {DT_FLOAT64, "f8", 8, &toLabels<double>},
};

const LabelType* niftiLabelType(int datatype) {
    for (const LabelType& t : kLabelTypes)
        if (t.niftiType == datatype) return &t;
    return nullptr;
}

const LabelType* npyLabelType(std::string_view kind) {
    if (kind == "b1") kind = "u1";
    for (const LabelType& t : kLabelTypes)
        if (t.npyKind == kind) return &t;
    return nullptr;
}

// Voxel size along i, j, k, origin 0.
glm::dmat4 diagonal(glm::dvec3 size) {
    glm::dmat4 m(1.0);
    m[0][0] = size.x;
    m[1][1] = size.y;
    m[2][2] = size.z;
    return m;
}

// The voxel-to-world transform of a NIfTI image: its sform, else its qform,
// else diag(pixdim[1..3]); finite and not singular.
std::optional<Error> setNiftiTransform(const nifti_image& nim, const std::string& path, Volume& v) {
    if (nim.sform_code > 0) {
        v.voxelToWorld = fromNifti(nim.sto_xyz);
        v.transform = "sform";
    } else if (nim.qform_code > 0) {
        v.voxelToWorld = fromNifti(nim.qto_xyz);
        v.transform = "qform";
    } else {
        const double dx = std::fabs(nim.dx), dy = std::fabs(nim.dy), dz = std::fabs(nim.dz);
        if (!(dx > 0 && dy > 0 && dz > 0 && std::isfinite(dx) && std::isfinite(dy) && std::isfinite(dz)))
            return bad(path, "no sform/qform and pixdim[1..3] are not positive: no voxel size");
        v.voxelToWorld = diagonal({dx, dy, dz});
        v.transform = "pixdim";
    }
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(v.voxelToWorld[c][r]))
                return bad(path, v.transform + " has a non-finite entry");
    if (std::fabs(glm::determinant(glm::dmat3(v.voxelToWorld))) == 0.0)
        return bad(path, v.transform + " is singular (a voxel axis of length 0)");
    return std::nullopt;
}

}  // namespace

glm::dvec3 Volume::spacing() const {
    return {glm::length(glm::dvec3(voxelToWorld[0])), glm::length(glm::dvec3(voxelToWorld[1])),
            glm::length(glm::dvec3(voxelToWorld[2]))};
}

Result<Volume> loadNifti(const std::string& path) {
    {
        std::ifstream probe(path, std::ios::binary);
        if (!probe) return bad(path, "cannot open the file");
    }
    nifti_set_debug_level(0);
    std::unique_ptr<nifti_image, NiftiFree> nim(nifti_image_read(path.c_str(), 1));
    if (!nim) return bad(path, "not a readable NIfTI-1/NIfTI-2 file (libnifti2 rejected it)");
    if (!nim->data) return bad(path, "NIfTI file without voxel data");
    const int64_t nx = nim->nx, ny = std::max<int64_t>(nim->ny, 1), nz = std::max<int64_t>(nim->nz, 1);
    if (nim->ndim > 3) {
        for (int d = 4; d <= nim->ndim && d <= 7; ++d)
            if (nim->dim[d] > 1)
                return bad(path, "a " + std::to_string(nim->ndim) +
                                     "-D image with more than one volume (dim[" + std::to_string(d) +
                                     "] = " + std::to_string(nim->dim[d]) + "); masks are 3-D");
    }
    if (nx < 1 || uint64_t(nx) * uint64_t(ny) * uint64_t(nz) != uint64_t(nim->nvox))
        return bad(path, "inconsistent dimensions");
    Volume v;
    v.path = path;
    v.dims = {nx, ny, nz};
    if (auto e = setNiftiTransform(*nim, path, v)) return *e;
    const double slope = nim->scl_slope, inter = nim->scl_inter;
    const bool scale =
        std::isfinite(slope) && slope != 0.0 && std::isfinite(inter) && (slope != 1.0 || inter != 0.0);
    const size_t n = size_t(nim->nvox);
    if (nim->datatype == DT_UINT8 && !scale) {
        const uint8_t* raw = static_cast<const uint8_t*>(nim->data);
        v.labels8.assign(raw, raw + n);
        return v;
    }
    const LabelType* type = niftiLabelType(nim->datatype);
    if (type == nullptr) {
        return bad(path, std::string("voxel type ") + nifti_datatype_string(nim->datatype) +
                             " is not a label type (integers or float32/float64)");
    }
    if (auto e = type->toLabels(nim->data, n, scale, slope, inter, path, v.labels)) return *e;
    return v;
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
        if (end == at) return bad(path, ".npy shape '" + shape + "' is malformed");
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
        return bad(path, "not a .npy file");
    const int major = uint8_t(bytes[6]);
    size_t headerLen = 0, headerAt = 0;
    if (major == 1) {
        headerLen = uint8_t(bytes[8]) | (size_t(uint8_t(bytes[9])) << 8);
        headerAt = 10;
    } else if (major == 2 || major == 3) {
        if (bytes.size() < 12) return bad(path, "truncated .npy header");
        for (int i = 0; i < 4; ++i) headerLen |= size_t(uint8_t(bytes[8 + i])) << (8 * i);
        headerAt = 12;
    } else {
        return bad(path, ".npy format version " + std::to_string(major) + " is not supported");
    }
    if (bytes.size() < headerAt + headerLen) return bad(path, "truncated .npy header");
    const std::string header(bytes.data() + headerAt, headerLen);
    const auto descr = dictValue(header, "descr");
    const auto order = dictValue(header, "fortran_order");
    const auto shape = dictValue(header, "shape");
    if (!descr || !order || !shape) return bad(path, ".npy header without descr/fortran_order/shape");
    const Result<std::vector<int64_t>> dims = parseShape(*shape, path);
    if (!dims) return dims.error();
    if (dims->size() != 3)
        return bad(path, ".npy array has " + std::to_string(dims->size()) + " axes; masks are 3-D");
    return NpyHeader{headerAt + headerLen,
                     *descr,
                     order->find("True") != std::string::npos,
                     {(*dims)[0], (*dims)[1], (*dims)[2]}};
}

// The label type of a .npy dtype: little-endian, or one byte in any order.
Result<const LabelType*> npyType(const std::string& d, const std::string& path) {
    if (d.size() < 3) return bad(path, ".npy dtype '" + d + "' is not supported");
    if (d[0] == '>' && d.substr(1) != "u1" && d.substr(1) != "i1" && d.substr(1) != "b1")
        return bad(path, "big-endian .npy arrays are not supported (dtype '" + d + "')");
    const LabelType* type = npyLabelType(std::string_view(d).substr(1));
    if (type == nullptr) return bad(path, ".npy dtype '" + d + "' is not a label type");
    return type;
}

// A C-order array ((i, j, k) at (i * n1 + j) * n2 + k) stored i fastest.
template <class T>
void fromCOrder(const T* in, const std::array<int64_t, 3>& dims, T* out) {
    const int64_t n0 = dims[0], n1 = dims[1], n2 = dims[2];
    for (int64_t i = 0; i < n0; ++i)
        for (int64_t j = 0; j < n1; ++j)
            for (int64_t k = 0; k < n2; ++k)
                out[size_t(i + n0 * (j + n1 * k))] = in[size_t((i * n1 + j) * n2 + k)];
}

// The array's labels into v, i fastest: bool and uint8 as bytes (labels8),
// the other types converted to int32.
std::optional<Error> readNpyLabels(const std::vector<char>& bytes, const NpyHeader& h, const LabelType& type,
                                   const std::string& path, Volume& v) {
    const uint64_t n = uint64_t(h.dims[0]) * uint64_t(h.dims[1]) * uint64_t(h.dims[2]);
    if (bytes.size() - h.dataAt < n * type.bytes)
        return bad(path, ".npy data is truncated (" + std::to_string(bytes.size() - h.dataAt) +
                             " bytes for " + std::to_string(n) + " voxels of " + std::to_string(type.bytes) +
                             " bytes)");
    const char* raw = bytes.data() + h.dataAt;
    if (type.npyKind == "u1") {
        const uint8_t* b8 = reinterpret_cast<const uint8_t*>(raw);
        v.labels8.resize(n);
        if (h.fortran) {
            std::copy(b8, b8 + n, v.labels8.begin());
        } else {
            fromCOrder(b8, h.dims, v.labels8.data());
        }
        return std::nullopt;
    }
    std::vector<int32_t> flat;
    if (auto e = type.toLabels(raw, n, false, 1, 0, path, flat)) return e;
    if (h.fortran) {
        v.labels = std::move(flat);  // already i fastest
    } else {
        v.labels.resize(n);
        fromCOrder(flat.data(), h.dims, v.labels.data());
    }
    return std::nullopt;
}

}  // namespace

Result<Volume> loadNpy(const std::string& path, glm::dvec3 spacing, const std::optional<glm::dmat4>& affine) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return bad(path, "cannot open the file");
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
        v.voxelToWorld = diagonal(spacing);
        v.transform = "spacing";
    }
    return v;
}

Result<Volume> loadVolume(const std::string& path, glm::dvec3 spacing,
                          const std::optional<glm::dmat4>& affine) {
    if (endsWith(path, ".npy")) return loadNpy(path, spacing, affine);
    if (endsWith(path, ".nii") || endsWith(path, ".nii.gz")) return loadNifti(path);
    return bad(path, "unknown volume format (expected .nii, .nii.gz or .npy)");
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
