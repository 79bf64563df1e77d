// rthdist-utm-site: the README's precision example (issue 10). Writes two
// samplings of a 200 m terrain at UTM coordinates (x ~ 5.1e5, y ~ 5.4e6,
// centimetre detail) as double binary PLYs and prints the Hausdorff distance
// by a brute force in double, to compare with `rthdist PREFIX_a.ply
// PREFIX_b.ply` (float32 spacing at y = 5.4e6 is 0.5 m: a float path misses).
//
//   rthdist-utm-site PREFIX [POINTS_A POINTS_B]   (default 20000 5000)
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

struct Point {
    double x, y, z;
};

// splitmix64: a fixed sequence on every platform (std distributions are not).
class Sequence {
public:
    explicit Sequence(uint64_t seed) : m_state(seed) {}
    double uniform() {  // [0, 1)
        uint64_t z = (m_state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return double((z ^ (z >> 31)) >> 11) * 0x1p-53;
    }

private:
    uint64_t m_state;
};

constexpr double kEasting = 512345.0;
constexpr double kNorthing = 5403210.0;
constexpr double kExtent = 200.0;
constexpr double kDetail = 0.01;  // centimetres

double roundTo(double v, double step) { return std::round(v / step) * step; }

// n random places on a rolling terrain, coordinates rounded to centimetres.
std::vector<Point> sampleSite(uint64_t seed, size_t n) {
    Sequence s(seed);
    std::vector<Point> points(n);
    for (Point& p : points) {
        const double u = s.uniform() * kExtent, v = s.uniform() * kExtent;
        const double z =
            120.0 + 6.0 * std::sin(u / 23.0) * std::cos(v / 31.0) + 0.8 * std::sin(u / 3.1 + v / 4.3);
        p = {roundTo(kEasting + u, kDetail), roundTo(kNorthing + v, kDetail), roundTo(z, kDetail)};
    }
    return points;
}

bool writeDoublePly(const std::string& path, const std::vector<Point>& points) {
    FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return false;
    std::fprintf(f,
                 "ply\nformat binary_little_endian 1.0\ncomment rthdist-utm-site: 200 m at UTM, cm detail\n"
                 "element vertex %zu\nproperty double x\nproperty double y\nproperty double z\nend_header\n",
                 points.size());
    bool ok = true;
    for (const Point& p : points) {
        const double xyz[3] = {p.x, p.y, p.z};  // x86/ARM: little endian
        ok = ok && std::fwrite(xyz, sizeof xyz, 1, f) == 1;
    }
    return std::fclose(f) == 0 && ok;
}

struct Directed {
    double distance = -1.0;
    size_t query = 0, target = 0;
};

Directed bruteForce(const std::vector<Point>& q, const std::vector<Point>& t) {
    Directed out;
    for (size_t i = 0; i < q.size(); ++i) {
        double best = INFINITY;
        size_t bestJ = 0;
        for (size_t j = 0; j < t.size(); ++j) {
            const double dx = q[i].x - t[j].x, dy = q[i].y - t[j].y, dz = q[i].z - t[j].z;
            const double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 < best) {
                best = d2;
                bestJ = j;
            }
        }
        if (std::sqrt(best) > out.distance) out = {std::sqrt(best), i, bestJ};
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2 && argc != 4) {
        std::fprintf(stderr, "usage: rthdist-utm-site PREFIX [POINTS_A POINTS_B]\n");
        return 2;
    }
    const std::string prefix = argv[1];
    const size_t nA = argc == 4 ? std::strtoull(argv[2], nullptr, 10) : 20000;
    const size_t nB = argc == 4 ? std::strtoull(argv[3], nullptr, 10) : 5000;
    if (nA == 0 || nB == 0) {
        std::fprintf(stderr, "rthdist-utm-site: point counts must be positive\n");
        return 2;
    }
    const std::vector<Point> a = sampleSite(1, nA), b = sampleSite(2, nB);
    for (const auto& [name, points] : {std::pair{prefix + "_a.ply", &a}, std::pair{prefix + "_b.ply", &b}}) {
        if (!writeDoublePly(name, *points)) {
            std::fprintf(stderr, "rthdist-utm-site: cannot write %s\n", name.c_str());
            return 5;
        }
    }
    const Directed ab = bruteForce(a, b), ba = bruteForce(b, a);
    std::printf("A %s_a.ply (%zu points), B %s_b.ply (%zu points)\n", prefix.c_str(), nA, prefix.c_str(), nB);
    std::printf(
        "double brute force: H = %.17g\n  h(A,B) = %.17g  A[%zu] -> B[%zu]\n  h(B,A) = %.17g  B[%zu] -> "
        "A[%zu]\n",
        std::max(ab.distance, ba.distance), ab.distance, ab.query, ab.target, ba.distance, ba.query,
        ba.target);
    return 0;
}
