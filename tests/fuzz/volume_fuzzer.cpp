// libFuzzer target for one volume reader of rthdist-masks, chosen at build
// time by RTHDIST_FUZZ_FORMAT: "nifti" (the NIfTI-1/2 header validation,
// then the reader: a plain .nii or a .nii.gz, zlib decides) or "npy" (the
// .npy header as NumPy's format specification says, then the array). The
// readers take a path to a regular file, so each input is written to a
// memfd and read through /proc/self/fd/N (no disk, nothing left behind).
//
// Any input must give a volume or a kBadInput error naming the file; a
// crash, a sanitizer report, a leak, a timeout or an allocation beyond
// -rss_limit_mb is a bug, and so is a volume whose labels do not match its
// dims or whose geometry the checks (masks::checkVolume) refuse.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "rthdist/masks.hpp"

#ifndef RTHDIST_FUZZ_FORMAT
#error "RTHDIST_FUZZ_FORMAT must name the format (nifti, npy)"
#endif

namespace {

constexpr std::string_view kFormat = RTHDIST_FUZZ_FORMAT;

// A small cap keeps each run fast: what the limit refuses is checked
// before anything is allocated, whatever its value.
constexpr uint64_t kFuzzVolumeBytes = uint64_t{1} << 20;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace rthdist;
    static const int fd = [] {
        const int f = ::memfd_create("rthdist_fuzz_volume", MFD_CLOEXEC);
        if (f < 0) std::abort();
        return f;
    }();
    if (::ftruncate(fd, 0) != 0 || ::lseek(fd, 0, SEEK_SET) != 0) std::abort();
    for (size_t at = 0; at < size;) {
        const ssize_t w = ::write(fd, data + at, size - at);
        if (w <= 0) std::abort();
        at += size_t(w);
    }
    const std::string path = "/proc/self/fd/" + std::to_string(fd);
    masks::VolumeLimits limits;
    limits.maxVolumeBytes = kFuzzVolumeBytes;
    const Result<masks::Volume> v =
        kFormat == "nifti" ? masks::loadNifti(path, limits)
                           : masks::loadNpy(path, glm::dvec3(0.5, 1.0, 2.0), std::nullopt, limits);
    if (!v) {
        if (v.error().code != ErrorCode::kBadInput) std::abort();
        if (v.error().message.compare(0, path.size(), path) != 0) std::abort();  // names the file
        return 0;
    }
    if (masks::checkVolume(*v)) std::abort();
    if (v->voxelCount() * (v->labels8.empty() ? 4 : 1) > kFuzzVolumeBytes) std::abort();
    return 0;
}
