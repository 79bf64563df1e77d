// rthdist-scale-gen: the seeded inputs of the scale suite
// (tools/bench/gpu_scale_suite.sh), written as binary little-endian float PLY
// on all cores. Each block of 2^20 points draws from its own generator
// (splitmix64 started at a hash of the set's seed and the block number), so a file
// depends only on (shape, n, seed), not on the thread count.
//
//   rthdist-scale-gen SHAPE N SEED OUT.ply
//
// Shapes (coordinates in metres where it matters):
//   torus    area-uniform on the torus R = 1, r = 0.3, Gaussian noise
//            (sigma 1e-4) on the minor radius (issue 32's torus)
//   shell    uniform on the unit sphere, Gaussian noise (sigma 1e-4) on the radius
//   crowded  a sphere of radius 0.05 at (0.5, 0.5, 0.5), noise sigma 2e-5 per
//            axis, and the unit box's corners (0,0,0) and (1,1,1) as points 0, 1
//   cluster  uniform in a 2 mm cube at the origin, and 10 far points 1-10 km
//            away (the last 10 points)
//   cube     uniform in the unit cube
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

namespace {

struct Rng {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    double gauss() {
        const double u = std::max(uniform(), 1e-300), v = uniform();
        return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
    }
};

constexpr uint64_t kBlock = uint64_t(1) << 20;
constexpr double kPi = std::numbers::pi;

void point(const std::string& shape, Rng& rng, uint64_t i, uint64_t n, float* out) {
    double p[3];
    if (shape == "torus") {
        for (;;) {
            const double u = rng.uniform() * 2 * kPi, v = rng.uniform() * 2 * kPi;
            if (rng.uniform() * 1.3 >= 1.0 + 0.3 * std::cos(v)) continue;  // area density
            const double r = 0.3 + 1e-4 * rng.gauss(), ring = 1.0 + r * std::cos(v);
            p[0] = ring * std::cos(u);
            p[1] = ring * std::sin(u);
            p[2] = r * std::sin(v);
            break;
        }
    } else if (shape == "shell" || shape == "crowded") {
        double d[3], len = 0.0;
        do {
            for (double& c : d) c = rng.gauss();
            len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        } while (len < 1e-9);
        if (shape == "shell") {
            const double r = 1.0 + 1e-4 * rng.gauss();
            for (int k = 0; k < 3; ++k) p[k] = r * d[k] / len;
        } else {
            for (int k = 0; k < 3; ++k) p[k] = 0.5 + 0.05 * d[k] / len + 2e-5 * rng.gauss();
            if (i < 2) p[0] = p[1] = p[2] = double(i);  // the box's corners
        }
    } else if (shape == "cluster") {
        if (i + 10 < n) {
            for (double& c : p) c = 2e-3 * rng.uniform();
        } else {
            double d[3], len = 0.0;
            do {
                for (double& c : d) c = rng.gauss();
                len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            } while (len < 1e-9);
            const double r = 1000.0 + 9000.0 * rng.uniform();
            for (int k = 0; k < 3; ++k) p[k] = r * d[k] / len;
        }
    } else {  // cube
        for (double& c : p) c = rng.uniform();
    }
    for (int k = 0; k < 3; ++k) out[k] = float(p[k]);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: rthdist-scale-gen torus|shell|crowded|cluster|cube N SEED OUT.ply\n");
        return 2;
    }
    const std::string shape = argv[1];
    if (shape != "torus" && shape != "shell" && shape != "crowded" && shape != "cluster" && shape != "cube") {
        std::fprintf(stderr, "rthdist-scale-gen: unknown shape '%s'\n", argv[1]);
        return 2;
    }
    const uint64_t n = std::strtoull(argv[2], nullptr, 10), seed = std::strtoull(argv[3], nullptr, 10);
    if (n < 12) {
        std::fprintf(stderr, "rthdist-scale-gen: N must be at least 12\n");
        return 2;
    }
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n) +
                               "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    const uint64_t bytes = header.size() + n * 12;
    const int fd = ::open(argv[4], O_RDWR | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || ::ftruncate(fd, off_t(bytes)) != 0) {
        std::perror(argv[4]);
        return 1;
    }
    void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (map == MAP_FAILED) {
        std::perror("mmap");
        return 1;
    }
    char* base = static_cast<char*>(map);
    std::memcpy(base, header.data(), header.size());
    float* pts = reinterpret_cast<float*>(base + header.size());  // unaligned is fine on x86-64
    const uint64_t blocks = (n + kBlock - 1) / kBlock;
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (uint64_t b = t; b < blocks; b += threads) {
                // The block's stream starts at a hashed place of splitmix64's
                // cycle (consecutive states would give shifted copies).
                Rng rng{Rng{seed}.next() ^ Rng{~b}.next()};
                float xyz[3];
                for (uint64_t i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i) {
                    point(shape, rng, i, n, xyz);
                    std::memcpy(pts + 3 * i, xyz, sizeof xyz);
                }
            }
        });
    for (std::thread& th : pool) th.join();
    if (::munmap(map, bytes) != 0 || ::close(fd) != 0) {
        std::perror(argv[4]);
        return 1;
    }
    return 0;
}
