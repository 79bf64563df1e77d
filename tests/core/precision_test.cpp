// Exact on the user's own coordinates (issue 10): double inputs far from the
// origin against a double brute force on the CPU backend (the GPU backends
// run the same cases in tests/gpu_algo), point views with strides, and proof that
// the cases need the shift: rounding the doubles to float32 misses the truth.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cstring>
#include <vector>

#include "common/geo_cases.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::test {
namespace {

Options cpuOptions() {
    Options o;
    o.backend = Backend::kCpu;
    return o;
}

TEST(Precision, GeoreferencedDoublesMatchTheDoubleBruteForce) {
    for (const GeoCase& c : makeGeoCases()) {
        auto r = hausdorff(c.a, c.b, cpuOptions());
        ASSERT_TRUE(r) << c.name << ": " << r.error().message;
        expectMatchesGeoOracle(c, *r);
        EXPECT_NE(r->origin, glm::dvec3(0.0)) << "double input is shifted";
    }
}

TEST(Precision, RoundingToFloatWithoutTheShiftMissesTheTruth) {
    // The failure the shift removes: utm_cm cases rounded to float32 at their
    // own coordinates (0.5 m spacing at y ~ 5.4e6) are off by far more than
    // the tolerance 1e-6 * diagonal (about 0.3 mm).
    int missed = 0, utm = 0;
    for (const GeoCase& c : makeGeoCases()) {
        if (c.name.rfind("utm_cm", 0) != 0) continue;
        ++utm;
        std::vector<glm::vec3> fa(c.a.begin(), c.a.end()), fb(c.b.begin(), c.b.end());
        auto rounded = hausdorff(fa, fb, cpuOptions());
        ASSERT_TRUE(rounded);
        const double truth = std::max(bruteForceDirectedDouble(c.a, c.b).distance,
                                      bruteForceDirectedDouble(c.b, c.a).distance);
        if (std::fabs(rounded->hausdorff - truth) > 1e-3) ++missed;
    }
    EXPECT_EQ(missed, utm);
}

// A vertex buffer: position, normal, colour. The view reads the positions
// in place; the result equals that of packed copies.
struct Vertex {
    float position[3];
    float normal[3];
    uint8_t rgba[4];
};

TEST(Precision, StridedViewsReadInPlace) {
    const GeoCase c = makeGeoCases()[7];
    std::vector<Vertex> va(c.a.size()), vb(c.b.size());
    std::vector<glm::vec3> pa, pb;
    for (size_t i = 0; i < va.size(); ++i) {
        const glm::vec3 p(c.a[i] - c.a[0]);
        std::memcpy(va[i].position, &p, sizeof(p));
        pa.push_back(p);
    }
    for (size_t i = 0; i < vb.size(); ++i) {
        const glm::vec3 p(c.b[i] - c.a[0]);
        std::memcpy(vb[i].position, &p, sizeof(p));
        pb.push_back(p);
    }
    auto strided = hausdorff(PointView::floats(va[0].position, va.size(), sizeof(Vertex)),
                             PointView::floats(vb[0].position, vb.size(), sizeof(Vertex)), cpuOptions());
    auto packed = hausdorff(pa, pb, cpuOptions());
    ASSERT_TRUE(strided && packed);
    EXPECT_EQ(strided->hausdorff, packed->hausdorff);
    EXPECT_EQ(strided->aToB.queryIndex, packed->aToB.queryIndex);
    EXPECT_EQ(strided->bToA.targetPoint, packed->bToA.targetPoint);

    // An (N,4) double array, as a NumPy slice a[:, :3] would give.
    std::vector<double> wide;
    for (const glm::dvec3& p : c.a) wide.insert(wide.end(), {p.x, p.y, p.z, -1.0});
    auto doubles =
        hausdorff(PointView::doubles(wide.data(), c.a.size(), 4 * sizeof(double)), c.b, cpuOptions());
    auto reference = hausdorff(c.a, c.b, cpuOptions());
    ASSERT_TRUE(doubles && reference);
    EXPECT_EQ(doubles->hausdorff, reference->hausdorff);
}

TEST(Precision, BadViewsAreRefusedNamingTheSet) {
    std::vector<float> xyz{0, 0, 0, 1, 1, 1};
    auto tooNarrow = hausdorff(PointView::floats(xyz.data(), 2, 8), PointView::floats(xyz.data(), 2));
    ASSERT_FALSE(tooNarrow);
    EXPECT_EQ(tooNarrow.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(tooNarrow.error().message.find("point set A"), std::string::npos) << tooNarrow.error().message;
    std::vector<double> nan{0, 0, 0, 1, std::nan(""), 1};
    auto withNan =
        hausdorff(PointView::floats(xyz.data(), 2), PointView::doubles(nan.data(), 2), cpuOptions());
    ASSERT_FALSE(withNan);
    EXPECT_NE(withNan.error().message.find("point set B: point 1"), std::string::npos)
        << withNan.error().message;
}

}  // namespace
}  // namespace rthdist::test
