#include "cli/per_point_files.hpp"

#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace rthdist::cli {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

Error cannotWrite(const std::string& path) { return Error{ErrorCode::kBadInput, path + ": cannot write"}; }

Result<bool> writeAll(const std::string& path, const std::string& bytes) {
    File f(std::fopen(path.c_str(), "wb"));
    if (!f) return cannotWrite(path);
    if (std::fwrite(bytes.data(), 1, bytes.size(), f.get()) != bytes.size()) return cannotWrite(path);
    if (std::fclose(f.release()) != 0) return cannotWrite(path);
    return true;
}

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

}  // namespace

Result<bool> writeDistancePly(const std::string& path, std::span<const glm::vec3> points,
                              const PerPoint& nearest, const ColourRange& range) {
    if (nearest.distance.size() != points.size()) {
        return Error{ErrorCode::kInvalidArgument, path + ": per-point distances missing"};
    }
    std::string out =
        "ply\nformat binary_little_endian 1.0\ncomment rthdist per-point nearest distance\n"
        "comment quality = exact distance to the nearest point of the other set\n"
        "comment colour range " +
        std::to_string(range.lo) + " " + std::to_string(range.hi) + "\nelement vertex " +
        std::to_string(points.size()) +
        "\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    out.reserve(out.size() + points.size() * 19);
    for (size_t i = 0; i < points.size(); ++i) {
        appendLe(out, points[i].x);
        appendLe(out, points[i].y);
        appendLe(out, points[i].z);
        appendLe(out, float(nearest.distance[i]));
        const Rgb c = distanceColour(nearest.distance[i], range);
        out.push_back(char(c.r));
        out.push_back(char(c.g));
        out.push_back(char(c.b));
    }
    return writeAll(path, out);
}

Result<bool> writeDistanceCsv(const std::string& path, std::span<const glm::vec3> points,
                              const PerPoint& nearest) {
    if (nearest.distance.size() != points.size() || nearest.nearest.size() != points.size()) {
        return Error{ErrorCode::kInvalidArgument, path + ": per-point distances missing"};
    }
    std::string out = "index,x,y,z,distance,nearest\n";
    out.reserve(points.size() * 64);
    for (size_t i = 0; i < points.size(); ++i) {
        appendNumber(out, uint64_t(i));
        for (float c : {points[i].x, points[i].y, points[i].z}) {
            out.push_back(',');
            appendNumber(out, c);
        }
        out.push_back(',');
        appendNumber(out, nearest.distance[i]);
        out.push_back(',');
        appendNumber(out, uint64_t(nearest.nearest[i]));
        out.push_back('\n');
    }
    return writeAll(path, out);
}

}  // namespace rthdist::cli
