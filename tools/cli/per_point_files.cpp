#include "cli/per_point_files.hpp"

#include <charconv>
#include <cstring>
#include <string>
#include <vector>

#include "cli/output_file.hpp"

namespace rthdist::cli {
namespace {

template <class T>
void appendNumber(std::string& out, T v) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

template <class T>
void appendLe(std::string& out, T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));  // little-endian hosts only (x86-64, arm64)
    out.append(b, sizeof(T));
}

// A CSV row's first columns: index,x,y,z,distance (no line end); x, y, z
// in the input's precision (a float view's values are floats: the shortest
// float decimal; a double view's the shortest double decimal).
void appendRowStart(std::string& out, size_t index, const PointView& points, double distance) {
    appendNumber(out, uint64_t(index));
    const glm::dvec3 p = points.at(index);
    for (int k = 0; k < 3; ++k) {
        out.push_back(',');
        if (points.scalar == Scalar::kFloat32)
            appendNumber(out, float(p[k]));
        else
            appendNumber(out, p[k]);
    }
    out.push_back(',');
    appendNumber(out, distance);
}

}  // namespace

Result<bool> writeDistancePly(const std::string& path, std::span<const glm::vec3> points,
                              std::span<const double> distance, const ColourRange& range,
                              const std::string& quality) {
    if (distance.size() != points.size()) {
        return Error{ErrorCode::kInvalidArgument, path + ": per-point distances missing"};
    }
    std::string out =
        "ply\nformat binary_little_endian 1.0\ncomment rthdist per-point nearest distance\n"
        "comment quality = " +
        quality + "\ncomment colour range " + std::to_string(range.lo) + " " + std::to_string(range.hi) +
        "\nelement vertex " + std::to_string(points.size()) +
        "\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    out.reserve(out.size() + points.size() * 19);
    for (size_t i = 0; i < points.size(); ++i) {
        appendLe(out, points[i].x);
        appendLe(out, points[i].y);
        appendLe(out, points[i].z);
        appendLe(out, float(distance[i]));
        const Rgb c = distanceColour(distance[i], range);
        out.push_back(char(c.r));
        out.push_back(char(c.g));
        out.push_back(char(c.b));
    }
    return writeOutputFile(path, out);
}

Result<bool> writeDistanceCsv(const std::string& path, const PointView& points, const PerPoint& nearest) {
    if (nearest.distance.size() != points.size() || nearest.nearest.size() != points.size()) {
        return Error{ErrorCode::kInvalidArgument, path + ": per-point distances missing"};
    }
    std::string out = "index,x,y,z,distance,nearest\n";
    out.reserve(points.size() * 64);
    for (size_t i = 0; i < points.size(); ++i) {
        appendRowStart(out, i, points, nearest.distance[i]);
        out.push_back(',');
        appendNumber(out, uint64_t(nearest.nearest[i]));
        out.push_back('\n');
    }
    return writeOutputFile(path, out);
}

Result<bool> writeSurfaceCsv(const std::string& path, const PointView& points,
                             const SurfacePerPoint& nearest) {
    const size_t n = points.size();
    if (nearest.distance.size() != n || nearest.triangle.size() != n || nearest.closest.size() != n ||
        nearest.barycentric.size() != n) {
        return Error{ErrorCode::kInvalidArgument, path + ": per-point distances missing"};
    }
    std::string out =
        "index,x,y,z,distance,triangle,closest_x,closest_y,closest_z,barycentric_0,barycentric_1,"
        "barycentric_2\n";
    out.reserve(n * 160);
    for (size_t i = 0; i < n; ++i) {
        appendRowStart(out, i, points, nearest.distance[i]);
        out.push_back(',');
        appendNumber(out, uint64_t(nearest.triangle[i]));
        for (const glm::dvec3* v : {&nearest.closest[i], &nearest.barycentric[i]}) {
            for (int k = 0; k < 3; ++k) {
                out.push_back(',');
                appendNumber(out, (*v)[k]);
            }
        }
        out.push_back('\n');
    }
    return writeOutputFile(path, out);
}

}  // namespace rthdist::cli
