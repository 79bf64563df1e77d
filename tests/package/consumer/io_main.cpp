// The package's io component (rthdist::io, rthdist/io.hpp): writes a PLY,
// loads it back and checks that H to the original points is 0.
#include <rthdist/io.hpp>
#include <rthdist/rthdist.hpp>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

int main() {
    std::vector<glm::vec3> points = {{0.5f, 0, 0}, {1, 2, 3}, {-4, 5, -6}};
    const std::string path = (std::filesystem::temp_directory_path() / "rthdist_consumer_io.ply").string();
    if (auto written = rthdist::io::writePlyPoints(path, points); !written) {
        std::fprintf(stderr, "rthdist: %s\n", written.error().message.c_str());
        return 1;
    }
    rthdist::Result<rthdist::io::PointCloud> cloud = rthdist::io::loadPointCloud(path);
    std::filesystem::remove(path);
    if (!cloud) {
        std::fprintf(stderr, "rthdist: %s\n", cloud.error().message.c_str());
        return 1;
    }
    rthdist::Options options;
    options.backend = rthdist::Backend::kCpu;
    auto r = rthdist::hausdorff(cloud->view(), points, options);
    if (!r || cloud->size() != points.size() || r->hausdorff != 0.0) {
        std::fprintf(stderr, "round trip failed\n");
        return 1;
    }
    std::printf("io: %zu points read back, H = %g\n", cloud->size(), r->hausdorff);
    return 0;
}
