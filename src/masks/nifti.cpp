// NIfTI-1/2 label volumes through libnifti2 (Debian libnifti2-dev), and
// loadVolume (by extension). Apart from volume.cpp so that what reads arrays
// (the Python module) does not link libnifti2.
#include <nifti2_io.h>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string_view>
#include <utility>

#include "masks/label_types.hpp"
#include "masks/masks.hpp"

namespace rthdist::masks {
namespace {

using detail::badInput;

bool endsWith(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
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

// The label type of a NIfTI datatype (label_types.hpp), null when not a label type.
const detail::LabelType* niftiLabelType(int datatype) {
    constexpr std::pair<int, std::string_view> kKinds[] = {
        {DT_UINT8, "u1"}, {DT_INT8, "i1"},   {DT_UINT16, "u2"}, {DT_INT16, "i2"},   {DT_UINT32, "u4"},
        {DT_INT32, "i4"}, {DT_UINT64, "u8"}, {DT_INT64, "i8"},  {DT_FLOAT32, "f4"}, {DT_FLOAT64, "f8"},
    };
    for (const auto& [type, kind] : kKinds)
        if (type == datatype) return detail::labelType(kind);
    return nullptr;
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
            return badInput(path, "no sform/qform and pixdim[1..3] are not positive: no voxel size");
        v.voxelToWorld = detail::diagonalAffine({dx, dy, dz});
        v.transform = "pixdim";
    }
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(v.voxelToWorld[c][r]))
                return badInput(path, v.transform + " has a non-finite entry");
    if (std::fabs(glm::determinant(glm::dmat3(v.voxelToWorld))) == 0.0)
        return badInput(path, v.transform + " is singular (a voxel axis of length 0)");
    return std::nullopt;
}

}  // namespace

Result<Volume> loadNifti(const std::string& path) {
    {
        std::ifstream probe(path, std::ios::binary);
        if (!probe) return badInput(path, "cannot open the file");
    }
    nifti_set_debug_level(0);
    std::unique_ptr<nifti_image, NiftiFree> nim(nifti_image_read(path.c_str(), 1));
    if (!nim) return badInput(path, "not a readable NIfTI-1/NIfTI-2 file (libnifti2 rejected it)");
    if (!nim->data) return badInput(path, "NIfTI file without voxel data");
    const int64_t nx = nim->nx, ny = std::max<int64_t>(nim->ny, 1), nz = std::max<int64_t>(nim->nz, 1);
    if (nim->ndim > 3) {
        for (int d = 4; d <= nim->ndim && d <= 7; ++d)
            if (nim->dim[d] > 1)
                return badInput(path, "a " + std::to_string(nim->ndim) +
                                          "-D image with more than one volume (dim[" + std::to_string(d) +
                                          "] = " + std::to_string(nim->dim[d]) + "); masks are 3-D");
    }
    if (nx < 1 || uint64_t(nx) * uint64_t(ny) * uint64_t(nz) != uint64_t(nim->nvox))
        return badInput(path, "inconsistent dimensions");
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
    const detail::LabelType* type = niftiLabelType(nim->datatype);
    if (type == nullptr) {
        return badInput(path, std::string("voxel type ") + nifti_datatype_string(nim->datatype) +
                                  " is not a label type (integers or float32/float64)");
    }
    if (auto e = type->toLabels(nim->data, n, scale, slope, inter, path, v.labels)) return *e;
    return v;
}

Result<Volume> loadVolume(const std::string& path, glm::dvec3 spacing,
                          const std::optional<glm::dmat4>& affine) {
    if (endsWith(path, ".npy")) return loadNpy(path, spacing, affine);
    if (endsWith(path, ".nii") || endsWith(path, ".nii.gz")) return loadNifti(path);
    return badInput(path, "unknown volume format (expected .nii, .nii.gz or .npy)");
}

}  // namespace rthdist::masks
