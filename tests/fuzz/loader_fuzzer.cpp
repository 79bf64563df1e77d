// libFuzzer target for one point loader, chosen at build time by
// RTHDIST_FUZZ_FORMAT (tests/fuzz/CMakeLists.txt builds one binary per
// format). The readers take bytes, so every format is fed in memory; "gz"
// is a gzipped PLY: the bounded gunzip with the PLY header check, then the
// PLY reader, as loadPoints does for a .ply.gz.
//
// Any input must give points (and, for the formats with faces, triangles
// whose every index is below the vertex count) or a kBadInput error; a crash, a sanitizer
// report, a leak, a timeout or an allocation beyond -rss_limit_mb is a bug,
// and so is a result that changes with the parse's chunk size.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

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

bool sameCloud(const rthdist::io::PointCloud& a, const rthdist::io::PointCloud& b) {
    return a.scalar == b.scalar && a.floats.size() == b.floats.size() &&
           a.doubles.size() == b.doubles.size() &&
           // memcmp only on non-empty arrays: an empty vector's data() may be null.
           (a.floats.empty() ||
            std::memcmp(a.floats.data(), b.floats.data(), a.floats.size() * sizeof(glm::vec3)) == 0) &&
           (a.doubles.empty() ||
            std::memcmp(a.doubles.data(), b.doubles.data(), a.doubles.size() * sizeof(glm::dvec3)) == 0);
}

// The parallel parse must not depend on its chunks: read(plan) once with the
// whole input as one chunk and once with chunks of 1 to 16 bytes (record
// and line boundaries everywhere); the points or the error message must be
// the same, else abort (a finding).
template <class Read>
void differential(std::string_view bytes, Read&& read) {
    using rthdist::io::ChunkPlan;
    const auto whole = read(ChunkPlan{1, ~size_t(0)});
    const auto tiny = read(ChunkPlan{1, 1 + bytes.size() % 16});
    if (whole.ok() != tiny.ok()) std::abort();
    if (!whole.ok() && whole.error().message != tiny.error().message) std::abort();
    if (whole.ok() && !sameCloud(*whole, *tiny)) std::abort();
}

// loadMesh's face pass over the same bytes, after the vertices read: any
// input gives triangles (every index below the vertex count) or kBadInput.
template <class ReadFaces>
void faces(std::string_view bytes, const char* path, ReadFaces&& readFaces) {
    const auto cloud = [&] {
        using namespace rthdist::io;
        if (kFormat == "ply") return readPly(bytes, path);
        if (kFormat == "obj") return readObj(bytes, path);
        return readOff(bytes, path);
    }();
    if (!cloud.ok()) return;
    const auto triangles = readFaces(bytes, path, cloud->size());
    if (!triangles.ok()) return;
    if (triangles->size() % 3 != 0) std::abort();
    for (uint32_t v : *triangles) {
        if (v >= cloud->size()) std::abort();
    }
}

void loadBytes(std::string_view bytes) {
    using namespace rthdist::io;
    auto with = [&](auto reader, const char* path) {
        differential(bytes, [&](const ChunkPlan& plan) { return reader(bytes, path, plan); });
    };
    if (kFormat == "ply") with(&readPly, "fuzz.ply");
    if (kFormat == "ply") faces(bytes, "fuzz.ply", &readPlyFaces);
    if (kFormat == "xyz") with(&readXyz, "fuzz.xyz");
    if (kFormat == "obj") with(&readObj, "fuzz.obj");
    if (kFormat == "obj") faces(bytes, "fuzz.obj", &readObjFaces);
    if (kFormat == "stl") (void)readStl(bytes, "fuzz.stl");
    if (kFormat == "off") with(&readOff, "fuzz.off");
    if (kFormat == "off") faces(bytes, "fuzz.off", &readOffFaces);
    if (kFormat == "pcd") with(&readPcd, "fuzz.pcd");
    if (kFormat == "las") {
        for (const std::vector<int>& classes : {std::vector<int>{}, std::vector<int>{2, 6}}) {
            // The classification filter's two passes.
            differential(bytes,
                         [&](const ChunkPlan& plan) { return readLas(bytes, "fuzz.las", classes, plan); });
        }
    }
    if (kFormat == "gltf" || kFormat == "glb") {
        (void)readGltf(bytes, scratchDir() + "/fuzz." + std::string(kFormat));
        const auto mesh = readGltfMesh(bytes, scratchDir() + "/fuzz." + std::string(kFormat));
        if (mesh.ok()) {
            for (uint32_t v : mesh->triangles) {
                if (v >= mesh->points.size()) std::abort();
            }
        }
    }
}

void loadGzippedPly(std::string_view bytes) {
    using namespace rthdist::io;
    auto inflated = gunzip(bytes, "fuzz.ply.gz", &plyInflatedBound);
    if (inflated) {
        const std::string_view ply = *inflated;
        differential(ply, [&](const ChunkPlan& plan) { return readPly(ply, "fuzz.ply.gz", plan); });
    }
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
