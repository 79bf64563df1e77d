// NIfTI-1 (348 bytes) and NIfTI-2 (540 bytes) headers, validated field by
// field before any value is used (README "Segmentation masks", "NIfTI
// headers"): sizeof_hdr and magic (either byte order; single files 'n+1' /
// 'n+2' only), dim[0] in 1..7 and dim[1..dim[0]] >= 1 with one volume
// (dim[4..dim[0]] = 1), datatype a label type, vox_offset (integral, not
// inside the header, at most kNiftiMaxExtensionBytes past it), the pixdim
// a transform uses (finite, > 0; qfac pixdim[0] -1, 0 or 1), scl_slope /
// scl_inter, qform_code / sform_code in 0..5, quatern_b/c/d (b² + c² + d²
// <= 1), qoffset and srow finite, and the resulting grid (checkGrid:
// spacing and extent limits, not singular). Every error names the file,
// the field and the limit. No library reads the header: libnifti2 smashed
// its stack on dim[0] > 7 and turned NaN or zero pixdim into 1 mm.
#pragma once

#include <glm/mat4x4.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "masks/label_types.hpp"
#include "rthdist/result.hpp"

namespace rthdist::masks::detail {

inline constexpr size_t kNifti1HeaderBytes = 348;
inline constexpr size_t kNifti2HeaderBytes = 540;
// Extensions between the header and vox_offset are skipped (inflated, for
// .nii.gz): at most this many bytes of them.
inline constexpr uint64_t kNiftiMaxExtensionBytes = uint64_t{64} << 20;

struct NiftiHeader {
    int version = 1;  // 1 or 2
    std::array<int64_t, 3> dims{1, 1, 1};
    uint64_t voxels = 0;
    int datatype = 0;
    const LabelType* type = nullptr;
    std::string typeName;  // "uint8", ...
    uint64_t voxOffset = 0;
    LabelScale how;  // byte order and scaling
    glm::dmat4 voxelToWorld{1.0};
    std::string transform;  // "sform", "qform", "pixdim"
};

// The header's size from its first 4 bytes (sizeof_hdr, either byte order):
// 348 or 540; else kBadInput naming the file.
[[nodiscard]] Result<size_t> niftiHeaderBytes(std::string_view first, const std::string& path);

// `bytes`: the whole header (niftiHeaderBytes of them).
[[nodiscard]] Result<NiftiHeader> parseNiftiHeader(std::string_view bytes, const std::string& path);

}  // namespace rthdist::masks::detail
