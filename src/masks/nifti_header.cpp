// NIfTI header validation (nifti_header.hpp): each field read at its offset
// in the file's byte order, checked, and only then used.
#include "masks/nifti_header.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <type_traits>

namespace rthdist::masks::detail {
namespace {

// The fields' offsets: NIfTI-1 (nifti1.h) and NIfTI-2 (nifti2.h).
struct Layout {
    size_t dim, datatype, pixdim, voxOffset, sclSlope, sclInter, qformCode, sformCode, quatern, srow;
    bool wide;  // NIfTI-2: int64 dims, double floats, int32 codes
};
constexpr Layout kNifti1{40, 70, 76, 108, 112, 116, 252, 254, 256, 280, false};
constexpr Layout kNifti2{16, 12, 104, 168, 176, 184, 344, 348, 352, 400, true};

class Fields {
public:
    Fields(std::string_view bytes, bool swap) : m_bytes(bytes), m_swap(swap) {}

    template <class T>
    T at(size_t offset) const {
        unsigned char b[sizeof(T)];
        std::memcpy(b, m_bytes.data() + offset, sizeof(T));
        if (m_swap) std::reverse(b, b + sizeof(T));
        T t;
        std::memcpy(&t, b, sizeof(T));
        return t;
    }
    // An integer field: int16 (NIfTI-1) or int64 / int32 (NIfTI-2).
    int64_t integer(size_t offset, bool wide, bool code = false) const {
        if (!wide) return at<int16_t>(offset);
        return code ? int64_t(at<int32_t>(offset)) : at<int64_t>(offset);
    }
    // A floating-point field: float (NIfTI-1) or double (NIfTI-2).
    double real(size_t offset, bool wide) const {
        return wide ? at<double>(offset) : double(at<float>(offset));
    }

private:
    std::string_view m_bytes;
    bool m_swap;
};

std::string number(double v) {
    char t[40];
    std::snprintf(t, sizeof t, "%.9g", v);
    return t;
}

struct DataType {
    int code;
    const char* name;
    std::string_view kind;  // label_types.hpp kind, "" when not a label type
};
constexpr DataType kDataTypes[] = {
    {2, "uint8", "u1"},    {4, "int16", "i2"},     {8, "int32", "i4"},        {16, "float32", "f4"},
    {64, "float64", "f8"}, {256, "int8", "i1"},    {512, "uint16", "u2"},     {768, "uint32", "u4"},
    {1024, "int64", "i8"}, {1280, "uint64", "u8"}, {1, "binary (1 bit)", ""}, {32, "complex64", ""},
    {128, "RGB24", ""},    {1536, "float128", ""}, {1792, "complex128", ""},  {2048, "complex256", ""},
    {2304, "RGBA32", ""},
};

}  // namespace

Result<size_t> niftiHeaderBytes(std::string_view first, const std::string& path) {
    if (first.size() < 4) return badInput(path, "not a NIfTI file (shorter than 4 bytes)");
    int32_t n = 0;
    std::memcpy(&n, first.data(), 4);
    int32_t swapped = 0;
    unsigned char b[4];
    std::memcpy(b, first.data(), 4);
    std::reverse(b, b + 4);
    std::memcpy(&swapped, b, 4);
    for (int32_t v : {n, swapped})
        if (v == int32_t(kNifti1HeaderBytes) || v == int32_t(kNifti2HeaderBytes)) return size_t(v);
    return badInput(path, "not a NIfTI-1/NIfTI-2 file: sizeof_hdr = " + std::to_string(n) +
                              ", not 348 or 540 in either byte order");
}

Result<NiftiHeader> parseNiftiHeader(std::string_view bytes, const std::string& path) {
    const Result<size_t> size = niftiHeaderBytes(bytes, path);
    if (!size) return size.error();
    if (bytes.size() < *size)
        return badInput(path, "NIfTI header is truncated (" + std::to_string(bytes.size()) + " of " +
                                  std::to_string(*size) + " bytes)");
    NiftiHeader h;
    h.version = *size == kNifti1HeaderBytes ? 1 : 2;
    const Layout& l = h.version == 1 ? kNifti1 : kNifti2;
    int32_t raw = 0;
    std::memcpy(&raw, bytes.data(), 4);
    h.how.swap = raw != int32_t(*size);
    const Fields f(bytes, h.how.swap);
    const std::string v = "NIfTI-" + std::to_string(h.version) + " header: ";
    auto fail = [&](const std::string& what) { return badInput(path, v + what); };

    // magic
    if (h.version == 1) {
        const std::string_view magic = bytes.substr(344, 4);
        if (magic == std::string_view("ni1\0", 4))
            return fail("magic 'ni1' is a .hdr/.img pair; only single .nii files ('n+1') are read");
        if (magic != std::string_view("n+1\0", 4)) return fail("magic is not 'n+1' (a single-file NIfTI-1)");
    } else {
        const std::string_view magic = bytes.substr(4, 8);
        if (magic == std::string_view("ni2\0\r\n\032\n", 8))
            return fail("magic 'ni2' is a .hdr/.img pair; only single .nii files ('n+2') are read");
        if (magic != std::string_view("n+2\0\r\n\032\n", 8))
            return fail("magic is not 'n+2\\0\\r\\n\\032\\n' (a single-file NIfTI-2)");
    }

    // dim
    int64_t dim[8];
    for (int d = 0; d < 8; ++d) dim[d] = f.integer(l.dim + size_t(d) * (l.wide ? 8 : 2), l.wide);
    if (dim[0] < 1 || dim[0] > 7)
        return fail("dim[0] = " + std::to_string(dim[0]) + " is outside 1..7 (the number of dimensions)");
    for (int d = 1; d <= dim[0]; ++d)
        if (dim[d] < 1)
            return fail("dim[" + std::to_string(d) + "] = " + std::to_string(dim[d]) +
                        " is not a positive size (dim[0] = " + std::to_string(dim[0]) + ")");
    for (int d = 4; d <= dim[0]; ++d)
        if (dim[d] != 1)
            return fail("dim[" + std::to_string(d) + "] = " + std::to_string(dim[d]) + ": a " +
                        std::to_string(dim[0]) + "-D image with more than one volume; masks are 3-D");
    const int ndim = int(dim[0]);
    h.dims = {dim[1], ndim >= 2 ? dim[2] : 1, ndim >= 3 ? dim[3] : 1};
    h.voxels = 1;
    for (int64_t n : h.dims)
        if (__builtin_mul_overflow(h.voxels, uint64_t(n), &h.voxels))
            return fail("dim[1..3] = " + std::to_string(h.dims[0]) + " x " + std::to_string(h.dims[1]) +
                        " x " + std::to_string(h.dims[2]) + ": the voxel count overflows 64 bits");

    // datatype
    h.datatype = int(f.at<int16_t>(l.datatype));
    for (const DataType& t : kDataTypes)
        if (t.code == h.datatype) {
            h.typeName = t.name;
            h.type = t.kind.empty() ? nullptr : labelType(t.kind);
        }
    if (h.type == nullptr)
        return fail(
            "datatype " + std::to_string(h.datatype) + (h.typeName.empty() ? "" : " (" + h.typeName + ")") +
            " is not a label type (uint8, int8, uint16, int16, uint32, int32, uint64, int64, float32, "
            "float64)");

    // vox_offset
    const double voxOffset = l.wide ? double(f.at<int64_t>(l.voxOffset)) : double(f.at<float>(l.voxOffset));
    if (!(voxOffset >= double(*size) && voxOffset <= double(*size + kNiftiMaxExtensionBytes) &&
          voxOffset == std::floor(voxOffset)))
        return fail("vox_offset = " + number(voxOffset) + " is not an integer in " + std::to_string(*size) +
                    ".." + std::to_string(*size + kNiftiMaxExtensionBytes) +
                    " (past the header, at most 64 MiB of extensions)");
    h.voxOffset = uint64_t(voxOffset);

    // scl_slope, scl_inter (as nibabel: a slope of 0 or not finite means no scaling)
    const double slope = f.real(l.sclSlope, l.wide), inter = f.real(l.sclInter, l.wide);
    if (std::isfinite(slope) && slope != 0.0) {
        if (!std::isfinite(inter))
            return fail("scl_inter = " + number(inter) + " is not finite while scl_slope = " + number(slope) +
                        " scales the voxels");
        h.how.scale = slope != 1.0 || inter != 0.0;
        h.how.slope = slope;
        h.how.inter = inter;
    }

    // qform_code, sform_code
    const int64_t qformCode = f.integer(l.qformCode, l.wide, true),
                  sformCode = f.integer(l.sformCode, l.wide, true);
    for (auto [name, code] : {std::pair{"qform_code", qformCode}, std::pair{"sform_code", sformCode}})
        if (code < 0 || code > 5)
            return fail(std::string(name) + " = " + std::to_string(code) +
                        " is outside 0..5 (NIFTI_XFORM_*)");
    h.transform = sformCode > 0 ? "sform" : qformCode > 0 ? "qform" : "pixdim";

    // pixdim: the voxel sizes of the image's axes, and of any axis the transform uses
    double pixdim[8];
    for (int d = 0; d < 8; ++d) pixdim[d] = f.real(l.pixdim + size_t(d) * (l.wide ? 8 : 4), l.wide);
    for (int d = 1; d <= 3; ++d)
        if ((d <= ndim || h.transform != "sform") && !(std::isfinite(pixdim[d]) && pixdim[d] > 0.0))
            return fail("pixdim[" + std::to_string(d) + "] = " + number(pixdim[d]) +
                        " is not a positive finite voxel size");

    glm::dmat4 m(1.0);
    if (h.transform == "sform") {
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) {
                const double x = f.real(l.srow + size_t(r * 4 + c) * (l.wide ? 8 : 4), l.wide);
                if (!std::isfinite(x))
                    return fail(std::string("srow_") + char('x' + r) + "[" + std::to_string(c) +
                                "] = " + number(x) + " is not finite");
                m[c][r] = x;
            }
    } else if (h.transform == "qform") {
        const char* names[6] = {"quatern_b", "quatern_c", "quatern_d", "qoffset_x", "qoffset_y", "qoffset_z"};
        double q[6];
        for (int i = 0; i < 6; ++i) {
            q[i] = f.real(l.quatern + size_t(i) * (l.wide ? 8 : 4), l.wide);
            if (!std::isfinite(q[i]))
                return fail(std::string(names[i]) + " = " + number(q[i]) + " is not finite");
        }
        const double qfac = pixdim[0];
        if (!(qfac == -1.0 || qfac == 0.0 || qfac == 1.0))
            return fail("pixdim[0] = " + number(qfac) + " (qfac) is not -1, 0 or 1");
        double b = q[0], c = q[1], d = q[2];
        const double bcd = b * b + c * c + d * d;
        // nibabel's threshold: b² + c² + d² may pass 1 by 3 float32 epsilons.
        if (bcd > 1.0 + 3.0 * 1.1920928955078125e-07)
            return fail("quatern_b/c/d = " + number(b) + ", " + number(c) + ", " + number(d) +
                        ": b² + c² + d² = " + number(bcd) + " exceeds 1 (not a rotation)");
        // The rotation of the NIfTI-1 standard (nifti1.h, method 2), as
        // libnifti computes it: a = sqrt(1 - b² - c² - d²), renormalized when
        // that is below 1e-7.
        double a = 1.0 - bcd;
        if (a < 1e-7) {
            a = 1.0 / std::sqrt(bcd);
            b *= a;
            c *= a;
            d *= a;
            a = 0.0;
        } else {
            a = std::sqrt(a);
        }
        const double xd = pixdim[1], yd = pixdim[2], zd = qfac < 0 ? -pixdim[3] : pixdim[3];
        const double r[3][3] = {
            {(a * a + b * b - c * c - d * d) * xd, 2.0 * (b * c - a * d) * yd, 2.0 * (b * d + a * c) * zd},
            {2.0 * (b * c + a * d) * xd, (a * a + c * c - b * b - d * d) * yd, 2.0 * (c * d - a * b) * zd},
            {2.0 * (b * d - a * c) * xd, 2.0 * (c * d + a * b) * yd, (a * a + d * d - c * c - b * b) * zd}};
        for (int row = 0; row < 3; ++row) {
            for (int col = 0; col < 3; ++col) m[col][row] = r[row][col];
            m[3][row] = q[3 + row];
        }
    } else {
        m = diagonalAffine({pixdim[1], pixdim[2], pixdim[3]});
    }
    h.voxelToWorld = m;
    if (auto e = checkGrid(h.dims, m, path, v + "the " + h.transform, ErrorCode::kBadInput)) return *e;
    return h;
}

}  // namespace rthdist::masks::detail
