// loadPointCloud: read (and gunzip), dispatch on the extension, then enforce
// the contract shared by every format: at least one point, every coordinate
// finite. loadPoints: the same, rounded to float.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>

#include "io/file_bytes.hpp"
#include "io/gltf_reader.hpp"
#include "io/io_error.hpp"
#include "io/las_reader.hpp"
#include "io/number_parse.hpp"
#include "io/obj_reader.hpp"
#include "io/off_reader.hpp"
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
// that caps a .gz before it is inflated.
struct Format {
    Result<PointCloud> (*read)(std::string_view, const std::string&, const LoadOptions&) = nullptr;
    InflatedBound gzipBound = nullptr;
};

template <Result<PointCloud> (*kRead)(std::string_view, const std::string&)>
Result<PointCloud> ignoreOptions(std::string_view bytes, const std::string& path, const LoadOptions&) {
    return kRead(bytes, path);
}

Result<PointCloud> readGltfCloud(std::string_view bytes, const std::string& path, const LoadOptions&) {
    auto points = readGltf(bytes, path);
    if (!points) return points.error();
    return PointCloud{Scalar::kFloat32, std::move(points).value(), {}};
}

Result<PointCloud> readLasCloud(std::string_view bytes, const std::string& path, const LoadOptions& options) {
    return readLas(bytes, path, options.lasClasses);
}

Format formatFor(const std::string& ext) {
    if (ext == ".ply") return {&ignoreOptions<&readPly>, &plyInflatedBound};
    if (ext == ".xyz" || ext == ".txt") return {&ignoreOptions<&readXyz>};
    if (ext == ".obj") return {&ignoreOptions<&readObj>};
    if (ext == ".gltf" || ext == ".glb") return {&readGltfCloud, &glbInflatedBound};
    if (ext == ".stl") return {&ignoreOptions<&readStl>, &stlInflatedBound};
    if (ext == ".off") return {&ignoreOptions<&readOff>};
    if (ext == ".pcd") return {&ignoreOptions<&readPcd>};
    if (ext == ".las") return {&readLasCloud};
    return {};
}

// The first coordinate that is NaN or infinite, as the error naming it.
template <class Vec>
std::optional<Error> firstNonFinite(const std::vector<Vec>& points, const std::string& path,
                                    const char* note) {
    for (size_t i = 0; i < points.size(); ++i) {
        const Vec& p = points[i];
        for (int axis = 0; axis < 3; ++axis) {
            if (!std::isfinite(p[axis])) {
                return badInput(path, "vertex " + std::to_string(i),
                                std::string("coordinate ") + "xyz"[axis] + " is " +
                                    (std::isnan(p[axis]) ? "NaN" : "infinite") + note);
            }
        }
    }
    return std::nullopt;
}

}  // namespace

Result<PointCloud> loadPointCloud(const std::string& path, const LoadOptions& options) {
    const std::string ext = formatExtension(path);
    if (ext == ".laz") return lazError(path, "file");
    const Format format = formatFor(ext);
    if (format.read == nullptr) {
        return badInput(path, "file",
                        "unsupported extension '" + ext +
                            "' (ply, xyz, txt, obj, gltf, glb, stl, off, pcd, las, optionally .gz)");
    }

    auto bytes = readFileBytes(path, format.gzipBound);
    if (!bytes) return bytes.error();
    if (bytes->empty()) return badInput(path, "file", "empty file");

    auto cloud = format.read(*bytes, path, options);
    if (!cloud) return cloud;
    if (cloud->size() == 0) return badInput(path, "file", "contains no points");
    const std::optional<Error> bad = cloud->scalar == Scalar::kFloat64
                                         ? firstNonFinite(cloud->doubles, path, "")
                                         : firstNonFinite(cloud->floats, path, " (or beyond float range)");
    if (bad) return *bad;
    return cloud;
}

Result<std::vector<glm::vec3>> loadPoints(const std::string& path) {
    auto cloud = loadPointCloud(path);
    if (!cloud) return cloud.error();
    if (cloud->scalar == Scalar::kFloat32) return std::move(cloud->floats);
    std::vector<glm::vec3> points(cloud->doubles.size());
    for (size_t i = 0; i < points.size(); ++i) {
        const glm::dvec3& p = cloud->doubles[i];
        points[i] = glm::vec3(narrowToFloat(p.x), narrowToFloat(p.y), narrowToFloat(p.z));
    }
    if (auto bad = firstNonFinite(points, path, " (or beyond float range)")) return *bad;
    return points;
}

}  // namespace rthdist::io
