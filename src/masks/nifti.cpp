// NIfTI-1/2 label volumes (.nii, .nii.gz) read by rthdist itself: the
// header validated field by field (nifti_header.hpp), then the voxels
// inflated (zlib; a plain .nii is read through the same gzread) a piece at
// a time straight into the Volume, never more than the header declares and
// the limit allows; and loadVolume (by extension). Apart from volume.cpp so
// that what reads arrays (the Python module) does not link zlib's reader.
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <memory>
#include <string_view>
#include <vector>

#include "masks/label_types.hpp"
#include "masks/nifti_header.hpp"
#include "masks/volume_file.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks {
namespace {

using detail::badInput;

bool endsWith(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct GzClose {
    void operator()(gzFile_s* g) const { gzclose(g); }
};

// A gzip (or plain: zlib reads it through) stream over the file's descriptor.
class Inflated {
public:
    Inflated(gzFile g, const std::string& path) : m_g(g), m_path(path) {}

    // Exactly n bytes into out, else the reason (corrupt stream, file ends early).
    std::optional<Error> read(void* out, size_t n, const std::string& what) {
        size_t got = 0;
        while (got < n) {
            const unsigned piece = unsigned(std::min<size_t>(n - got, size_t(1) << 30));
            const int r = gzread(m_g.get(), static_cast<char*>(out) + got, piece);
            if (r < 0) {
                int code = 0;
                const char* why = gzerror(m_g.get(), &code);
                return badInput(m_path, what + ": the gzip stream is corrupt (zlib: " +
                                            std::string(why ? why : "?") + ")");
            }
            if (r == 0) break;
            got += size_t(r);
        }
        if (got != n)
            return badInput(m_path, what + " is truncated (" + std::to_string(got) + " of " +
                                        std::to_string(n) + " bytes; the " +
                                        (direct() ? "file" : "inflated stream") + " ends early)");
        return std::nullopt;
    }
    bool direct() { return gzdirect(m_g.get()) != 0; }

private:
    std::unique_ptr<gzFile_s, GzClose> m_g;
    const std::string& m_path;
};

}  // namespace

Result<Volume> loadNifti(const std::string& path, const VolumeLimits& limits) {
    Result<detail::VolumeFile> file = detail::VolumeFile::open(path);
    if (!file) return file.error();
    const int fd = ::dup(file->fd());
    if (fd < 0) return badInput(path, "cannot read the file (dup failed)");
    gzFile g = gzdopen(fd, "rb");
    if (g == nullptr) {
        ::close(fd);
        return badInput(path, "cannot read the file (gzdopen failed)");
    }
    gzbuffer(g, 1u << 17);
    Inflated in(g, path);
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
    if (in.direct() && h->voxOffset + dataBytes > file->size())
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
    return v;
}

Result<Volume> loadVolume(const std::string& path, glm::dvec3 spacing,
                          const std::optional<glm::dmat4>& affine, const VolumeLimits& limits) {
    if (endsWith(path, ".npy")) return loadNpy(path, spacing, affine, limits);
    if (endsWith(path, ".nii") || endsWith(path, ".nii.gz")) return loadNifti(path, limits);
    return badInput(path, "unknown volume format (expected .nii, .nii.gz or .npy)");
}

}  // namespace rthdist::masks
