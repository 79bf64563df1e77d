// loadPointCloud: map (or read and gunzip), dispatch on the extension, then enforce
// the contract shared by every format: at least one point, every coordinate
// finite. loadPoints: the same, rounded to float. loadMesh: the vertices as
// loadPointCloud reads them and the format's faces from the same bytes.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <optional>

#include "io/file_bytes.hpp"
#include "io/gltf_reader.hpp"
#include "io/io_error.hpp"
#include "io/las_reader.hpp"
#include "io/load_tuning.hpp"
#include "io/non_finite.hpp"
#include "io/number_parse.hpp"
#include "io/obj_reader.hpp"
#include "io/off_reader.hpp"
#include "io/parallel_chunks.hpp"
#include "io/pcd_reader.hpp"
#include "io/ply_reader.hpp"
#include "io/stl_reader.hpp"
#include "io/xyz_reader.hpp"
#include "rthdist/io.hpp"

namespace rthdist::io {
namespace {

// Lower-case extension with a trailing ".gz" removed: "a.PLY.gz" -> ".ply".
std::string formatExtension(const std::string& path) {
    std::string name = path.substr(path.find_last_of('/') + 1);
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
    if (name.size() > 3 && name.ends_with(".gz")) name.resize(name.size() - 3);
    const size_t dot = name.find_last_of('.');
    return dot == std::string::npos ? std::string() : name.substr(dot);
}

// A reader and, for formats whose header bounds the file size, the check
// that caps a .gz before it is inflated. checksFinite: the reader returns
// only clouds whose every coordinate is finite (the binary readers check
// each chunk in the pass that writes it), so no second pass reads them.
struct Format {
    Result<PointCloud> (*read)(std::string_view, const std::string&, const LoadOptions&,
                               const ChunkPlan&) = nullptr;
    InflatedBound gzipBound = nullptr;
    bool checksFinite = false;
};

template <Result<PointCloud> (*kRead)(std::string_view, const std::string&, const ChunkPlan&)>
Result<PointCloud> withPlan(std::string_view bytes, const std::string& path, const LoadOptions&,
                            const ChunkPlan& plan) {
    return kRead(bytes, path, plan);
}

Result<PointCloud> readStlCloud(std::string_view bytes, const std::string& path, const LoadOptions&,
                                const ChunkPlan&) {
    return readStl(bytes, path);
}

Result<PointCloud> readGltfCloud(std::string_view bytes, const std::string& path, const LoadOptions&,
                                 const ChunkPlan&) {
    auto points = readGltf(bytes, path);
    if (!points) return points.error();
    return PointCloud{Scalar::kFloat32, std::move(points).value(), {}};
}

Result<PointCloud> readLasCloud(std::string_view bytes, const std::string& path, const LoadOptions& options,
                                const ChunkPlan& plan) {
    return readLas(bytes, path, options.lasClasses, plan);
}

Format formatFor(const std::string& ext) {
    if (ext == ".ply") return {&withPlan<&readPly>, &plyInflatedBound, true};
    if (ext == ".xyz" || ext == ".txt") return {&withPlan<&readXyz>};
    if (ext == ".obj") return {&withPlan<&readObj>};
    if (ext == ".gltf" || ext == ".glb") return {&readGltfCloud, &glbInflatedBound};
    if (ext == ".stl") return {&readStlCloud, &stlInflatedBound};
    if (ext == ".off") return {&withPlan<&readOff>};
    if (ext == ".pcd") return {&withPlan<&readPcd>, nullptr, true};
    if (ext == ".las") return {&readLasCloud, nullptr, true};
    return {};
}

}  // namespace

namespace {

// The file's bytes for a format (mapped, or read and gunzipped).
Result<FileBytes> formatBytes(const std::string& path, const Format& format, const LoadTuning& tuning) {
    auto bytes = openFileBytes(path, format.gzipBound, tuning.access);
    if (!bytes) return bytes.error();
    if (bytes->view().empty()) return badInput(path, "file", "empty file");
    return bytes;
}

// The contract shared by every format: at least one point, every coordinate
// finite (checked here unless the format's reader has).
std::optional<Error> checkCloud(const PointCloud& cloud, const Format& format, const std::string& path,
                                const ChunkPlan& plan) {
    if (cloud.size() == 0) return badInput(path, "file", "contains no points");
    if (format.checksFinite) return std::nullopt;
    return checkFiniteCloud(cloud, path, plan);
}

}  // namespace

Result<PointCloud> loadPointCloudTuned(const std::string& path, const LoadOptions& options,
                                       const LoadTuning& tuning) {
    const std::string ext = formatExtension(path);
    if (ext == ".laz") return lazError(path, "file");
    const Format format = formatFor(ext);
    if (format.read == nullptr) {
        return badInput(path, "file",
                        "unsupported extension '" + ext +
                            "' (ply, xyz, txt, obj, gltf, glb, stl, off, pcd, las, optionally .gz)");
    }
    auto bytes = formatBytes(path, format, tuning);
    if (!bytes) return bytes.error();
    const ChunkPlan plan{options.threads, tuning.chunkBytes};
    auto cloud = format.read(bytes->view(), path, options, plan);
    if (!cloud) return cloud;
    if (auto bad = checkCloud(*cloud, format, path, plan)) return *bad;
    return cloud;
}

namespace {

// Every facet's three vertices, in file order (STL shares no vertex).
std::vector<uint32_t> facetTriangles(size_t vertices) {
    std::vector<uint32_t> indices(vertices - vertices % 3);
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
    return indices;
}

Result<std::vector<uint32_t>> readFaces(const std::string& ext, std::string_view bytes,
                                        const std::string& path, uint64_t vertexCount) {
    if (ext == ".obj") return readObjFaces(bytes, path, vertexCount);
    if (ext == ".off") return readOffFaces(bytes, path, vertexCount);
    if (ext == ".ply") return readPlyFaces(bytes, path, vertexCount);
    return facetTriangles(size_t(vertexCount));  // .stl
}

}  // namespace

Result<TriangleMesh> loadMeshTuned(const std::string& path, const LoadOptions& options,
                                   const LoadTuning& tuning) {
    const std::string ext = formatExtension(path);
    const bool faces =
        ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl" || ext == ".gltf" || ext == ".glb";
    if (!faces) {
        return badInput(path, "file",
                        "'" + ext +
                            "' files have no faces: a surface needs a triangle mesh (obj, ply, off, stl, "
                            "gltf, glb, optionally .gz)");
    }
    const Format format = formatFor(ext);
    auto bytes = formatBytes(path, format, tuning);
    if (!bytes) return bytes.error();
    const ChunkPlan plan{options.threads, tuning.chunkBytes};
    TriangleMesh mesh;
    if (ext == ".gltf" || ext == ".glb") {
        auto gltf = readGltfMesh(bytes->view(), path);
        if (!gltf) return gltf.error();
        mesh.vertices = PointCloud{Scalar::kFloat32, std::move(gltf->points), {}};
        mesh.indices = std::move(gltf->triangles);
    } else {
        auto cloud = format.read(bytes->view(), path, options, plan);
        if (!cloud) return cloud.error();
        mesh.vertices = std::move(cloud).value();
    }
    if (auto bad = checkCloud(mesh.vertices, format, path, plan)) return *bad;
    if (mesh.vertices.size() > UINT32_MAX) {
        return badInput(path, "file",
                        std::to_string(mesh.vertices.size()) +
                            " vertices: a mesh holds at most 2^32 - 1 (32-bit triangle indices)");
    }
    if (ext != ".gltf" && ext != ".glb") {
        auto indices = readFaces(ext, bytes->view(), path, mesh.vertices.size());
        if (!indices) return indices.error();
        mesh.indices = std::move(indices).value();
    }
    if (mesh.indices.empty()) return badInput(path, "file", "has no triangles (a surface needs faces)");
    return mesh;
}

Result<TriangleMesh> loadMesh(const std::string& path, const LoadOptions& options) {
    return loadMeshTuned(path, options, LoadTuning{});
}

Result<PointCloud> loadPointCloud(const std::string& path, const LoadOptions& options) {
    return loadPointCloudTuned(path, options, LoadTuning{});
}

Result<std::vector<glm::vec3>> loadPoints(const std::string& path) {
    auto cloud = loadPointCloud(path);
    if (!cloud) return cloud.error();
    if (cloud->scalar == Scalar::kFloat32)
        return std::vector<glm::vec3>(cloud->floats.begin(), cloud->floats.end());
    const ChunkPlan plan;
    std::vector<glm::vec3> points(cloud->doubles.size());
    const uint64_t perChunk = plan.items(sizeof(glm::dvec3));
    const size_t chunks = chunkCount(points.size(), perChunk);
    (void)forEachChunk(chunks, plan, [&](size_t c) -> std::optional<Error> {
        const size_t end = static_cast<size_t>(std::min<uint64_t>(points.size(), (c + 1) * perChunk));
        for (size_t i = static_cast<size_t>(c * perChunk); i < end; ++i) {
            const glm::dvec3& p = cloud->doubles[i];
            points[i] = glm::vec3(narrowToFloat(p.x), narrowToFloat(p.y), narrowToFloat(p.z));
        }
        return std::nullopt;
    });
    if (auto bad = firstNonFinite(points.data(), points.size(), path, plan)) return *bad;
    return points;
}

}  // namespace rthdist::io
