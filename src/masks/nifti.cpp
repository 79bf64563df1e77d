// NIfTI-1/2 label volumes (.nii, .nii.gz) read by rthdist itself: the
// header validated field by field (nifti_header.hpp), then the voxels
// inflated (zlib, volume_stream.hpp; a plain .nii is read through the same
// stream) a piece at a time straight into the Volume, never more than the
// header declares and the limit allows, and a .nii.gz read to its verified
// end; and loadVolume (by extension). Apart from volume.cpp so that what
// reads arrays (the Python module) does not link zlib's reader.
#include <algorithm>
#include <string_view>
#include <vector>

#include "masks/label_types.hpp"
#include "masks/nifti_header.hpp"
#include "masks/volume_file.hpp"
#include "masks/volume_stream.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

using detail::badInput;

bool endsWith(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

Result<Volume> loadNifti(const std::string& path, const VolumeLimits& limits) {
    Result<detail::VolumeFile> file = detail::VolumeFile::open(path);
    if (!file) return file.error();
    detail::VolumeStream in(*file, path);
    if (auto e = in.open()) return *e;
    std::string header(4, '\0');
    if (auto e = in.read(header.data(), 4, "the NIfTI header")) return *e;
    const Result<size_t> size = detail::niftiHeaderBytes(header, path);
    if (!size) return size.error();
    header.resize(*size);
    if (auto e = in.read(header.data() + 4, *size - 4, "the NIfTI header")) return *e;
    const Result<detail::NiftiHeader> h = detail::parseNiftiHeader(header, path);
    if (!h) return h.error();
    const bool bytes8 = h->type->npyKind == "u1" && !h->how.scale;
    if (auto e = detail::checkVolumeBytes(path, h->voxels, h->type->bytes, bytes8 ? 1 : 4, h->typeName,
                                          limits.maxVolumeBytes))
        return *e;
    const uint64_t dataBytes = h->voxels * h->type->bytes;
    if (!in.gzip() && h->voxOffset + dataBytes > file->size())
        return badInput(path, "NIfTI data is truncated: vox_offset " + std::to_string(h->voxOffset) + " + " +
                                  std::to_string(h->voxels) + " voxels of " + h->typeName + " need " +
                                  std::to_string(h->voxOffset + dataBytes) + " bytes, the file has " +
                                  std::to_string(file->size()));
    // Extensions (up to vox_offset) are skipped.
    std::vector<char> buffer(size_t(std::min<uint64_t>(h->voxOffset - *size, uint64_t(1) << 20)));
    for (uint64_t skip = h->voxOffset - *size; skip > 0;) {
        const size_t piece = size_t(std::min<uint64_t>(skip, buffer.size()));
        if (auto e = in.read(buffer.data(), piece, "the NIfTI extensions before vox_offset")) return *e;
        skip -= piece;
    }
    Volume v;
    v.path = path;
    v.dims = h->dims;
    v.voxelToWorld = h->voxelToWorld;
    v.transform = h->transform;
    auto next = [&in, &buffer](size_t bytes) -> Result<const char*> {
        buffer.resize(bytes);
        if (auto e = in.read(buffer.data(), bytes, "the NIfTI voxel data")) return *e;
        return static_cast<const char*>(buffer.data());
    };
    if (auto e = detail::readVolumeLabels(next, v.dims, true, *h->type, h->how, path, v)) return *e;
    // A .nii.gz is read to its end: the trailer verified, nothing after the voxels.
    if (auto e = in.finish("the last voxel (vox_offset " + std::to_string(h->voxOffset) + " + " +
                           std::to_string(dataBytes) + " bytes)"))
        return *e;
    return v;
}

Result<Volume> loadVolume(const std::string& path, glm::dvec3 spacing,
                          const std::optional<glm::dmat4>& affine, const VolumeLimits& limits) {
    if (endsWith(path, ".npy")) return loadNpy(path, spacing, affine, limits);
    if (endsWith(path, ".nii") || endsWith(path, ".nii.gz")) return loadNifti(path, limits);
    return badInput(path, "unknown volume format (expected .nii, .nii.gz or .npy)");
}

}  // namespace rthdist::masks
