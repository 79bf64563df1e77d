// libFuzzer target for one point loader, chosen at build time by
// RTHDIST_FUZZ_FORMAT (tests/fuzz/CMakeLists.txt builds one binary per
// format). The readers take bytes, so every format is fed in memory; "gz"
// is a gzipped PLY: the bounded gunzip with the PLY header check, then the
// PLY reader, as loadPoints does for a .ply.gz.
//
// Any input must give points or a kBadInput error; a crash, a sanitizer
// report, a leak, a timeout or an allocation beyond -rss_limit_mb is a bug.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "io/gltf_reader.hpp"
#include "io/gzip_inflate.hpp"
#include "io/las_reader.hpp"
#include "io/obj_reader.hpp"
#include "io/off_reader.hpp"
#include "io/pcd_reader.hpp"
#include "io/ply_reader.hpp"
#include "io/stl_reader.hpp"
#include "io/xyz_reader.hpp"

#ifndef RTHDIST_FUZZ_FORMAT
#error "RTHDIST_FUZZ_FORMAT must name the format (ply, xyz, obj, gltf, glb, stl, off, pcd, las, gz)"
#endif

namespace {

constexpr std::string_view kFormat = RTHDIST_FUZZ_FORMAT;

// A private directory per process, holding one regular file that a glTF
// buffer URI may name ("pos.bin": three float points), so the URI resolver
// is reached with files that exist and files that do not.
const std::string& scratchDir() {
    static const std::string dir = [] {
        std::string tmpl = (std::filesystem::temp_directory_path() / "rthdist_fuzz_XXXXXX").string();
        if (::mkdtemp(tmpl.data()) == nullptr) std::abort();
        const float xyz[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
        std::ofstream(tmpl + "/pos.bin", std::ios::binary)
            .write(reinterpret_cast<const char*>(xyz), sizeof xyz);
        return tmpl;
    }();
    return dir;
}

void loadBytes(std::string_view bytes) {
    using namespace rthdist::io;
    if (kFormat == "ply") (void)readPly(bytes, "fuzz.ply");
    if (kFormat == "xyz") (void)readXyz(bytes, "fuzz.xyz");
    if (kFormat == "obj") (void)readObj(bytes, "fuzz.obj");
    if (kFormat == "stl") (void)readStl(bytes, "fuzz.stl");
    if (kFormat == "off") (void)readOff(bytes, "fuzz.off");
    if (kFormat == "pcd") (void)readPcd(bytes, "fuzz.pcd");
    if (kFormat == "las") {
        (void)readLas(bytes, "fuzz.las", {});
        (void)readLas(bytes, "fuzz.las", {2, 6});  // the classification filter's two passes
    }
    if (kFormat == "gltf" || kFormat == "glb") {
        (void)readGltf(bytes, scratchDir() + "/fuzz." + std::string(kFormat));
    }
}

void loadGzippedPly(std::string_view bytes) {
    using namespace rthdist::io;
    auto inflated = gunzip(bytes, "fuzz.ply.gz", &plyInflatedBound);
    if (inflated) (void)readPly(*inflated, "fuzz.ply.gz");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    if (kFormat == "gz") {
        loadGzippedPly(bytes);
    } else {
        loadBytes(bytes);
    }
    return 0;
}
