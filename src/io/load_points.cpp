// loadPoints: read (and gunzip), dispatch on the extension, then enforce the
// contract shared by every format: at least one point, every coordinate finite.
#include <algorithm>
#include <cctype>
#include <cmath>

#include "io/file_bytes.hpp"
#include "io/gltf_reader.hpp"
#include "io/io_error.hpp"
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
    Result<std::vector<glm::vec3>> (*read)(std::string_view, const std::string&) = nullptr;
    InflatedBound gzipBound = nullptr;
};

Format formatFor(const std::string& ext) {
    if (ext == ".ply") return {&readPly, &plyInflatedBound};
    if (ext == ".xyz" || ext == ".txt") return {&readXyz};
    if (ext == ".obj") return {&readObj};
    if (ext == ".gltf" || ext == ".glb") return {&readGltf, &glbInflatedBound};
    if (ext == ".stl") return {&readStl, &stlInflatedBound};
    if (ext == ".off") return {&readOff};
    if (ext == ".pcd") return {&readPcd};
    return {};
}

}  // namespace

Result<std::vector<glm::vec3>> loadPoints(const std::string& path) {
    const std::string ext = formatExtension(path);
    const Format format = formatFor(ext);
    if (format.read == nullptr) {
        return badInput(path, "file",
                        "unsupported extension '" + ext +
                            "' (ply, xyz, txt, obj, gltf, glb, stl, off, pcd, optionally .gz)");
    }

    auto bytes = readFileBytes(path, format.gzipBound);
    if (!bytes) return bytes.error();
    if (bytes->empty()) return badInput(path, "file", "empty file");

    auto points = format.read(*bytes, path);
    if (!points) return points;
    if (points->empty()) return badInput(path, "file", "contains no points");
    for (size_t i = 0; i < points->size(); ++i) {
        const glm::vec3& p = (*points)[i];
        for (int axis = 0; axis < 3; ++axis) {
            if (!std::isfinite(p[axis])) {
                return badInput(path, "vertex " + std::to_string(i),
                                std::string("coordinate ") + "xyz"[axis] + " is " +
                                    (std::isnan(p[axis]) ? "NaN" : "infinite") + " (or beyond float range)");
            }
        }
    }
    return points;
}

}  // namespace rthdist::io
