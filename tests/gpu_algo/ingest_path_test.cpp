// The device ingest path (ingest.comp, GpuHausdorff::computePacked): packed
// float arrays are checked, bounded and sampled on the device, other views
// on the host. Both paths must give the same index and the same answer, and
// the device must reject what the host rejects, with the same words.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/oracle_cases.hpp"
#include "common/scoped_env.hpp"
#include "gpu_test_support.hpp"

namespace rthdist::test {
namespace {

// The same points as a float view with a 16-byte stride: not packed, so the
// engine takes the host path (summary pass, host bit count, staging copy).
struct Strided {
    std::vector<float> data;
    PointView view;
    explicit Strided(const std::vector<glm::vec3>& p) : data(p.size() * 4, -1.0f) {
        for (size_t i = 0; i < p.size(); ++i) {
            data[4 * i] = p[i].x;
            data[4 * i + 1] = p[i].y;
            data[4 * i + 2] = p[i].z;
        }
        view = PointView::floats(data.data(), p.size(), 16);
    }
};

// The index (bit count, cells) and the value are the same. Which of several
// tied pairs is the witness, and how many queries the running maximum kills
// early, depend on the order of atomics on a parallel device (NVIDIA), so
// they are not compared; both witnesses are checked against the oracle.
void expectSameDirection(const Directed& device, const Directed& host) {
    EXPECT_EQ(device.distance, host.distance);
    EXPECT_EQ(device.counters.bits, host.counters.bits);
    EXPECT_EQ(device.counters.occupiedCells, host.counters.occupiedCells);
    EXPECT_EQ(device.counters.queries, host.counters.queries);
}

TEST(IngestPath, SameIndexAndAnswerAsTheHostPath) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    const std::vector<OracleCase> cases = makeOracleCases();
    int compared = 0;
    for (size_t k = 0; k < cases.size(); k += 7) {  // every family, a seventh of the cases
        const OracleCase& c = cases[k];
        SCOPED_TRACE(c.name);
        auto device = engine->compute(c.a, c.b);
        const Strided sa(c.a), sb(c.b);
        auto host = engine->compute(sa.view, sb.view);
        ASSERT_TRUE(device.ok()) << device.error().message;
        ASSERT_TRUE(host.ok()) << host.error().message;
        expectMatchesOracle(c, *device);
        expectMatchesOracle(c, *host);
        EXPECT_EQ(device->hausdorff, host->hausdorff);
        expectSameDirection(device->aToB, host->aToB);
        expectSameDirection(device->bToA, host->bToA);
        EXPECT_EQ(device->validationMessages, 0u);
        ++compared;
    }
    EXPECT_GT(compared, 40);
}

// The automatic bit count of the device path (probe_levels.comp, where the
// device has shaderFloat64; else a sample gathered for the host) equals the
// host path's on sets that stress it: points on the probe's cell boundaries
// (a lattice of binary fractions of the extent), every point a duplicate, a
// plane, a line, a cluster with outliers, and sizes around the sample
// stride's steps (every point sampled up to 65,535; every second from 65,536).
TEST(IngestPath, DeviceBitCountEqualsTheHostCount) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const auto lattice = [](int side, float step, float offset) {
        std::vector<glm::vec3> p;
        for (int x = 0; x < side; ++x)
            for (int y = 0; y < side; ++y)
                for (int z = 0; z < side; ++z) p.emplace_back(offset + x * step, offset + y * step, z * step);
        return p;
    };
    std::vector<std::pair<std::string, std::vector<glm::vec3>>> sets;
    sets.emplace_back("lattice 1/1024", lattice(40, 1.0f / 1024.0f, 0.0f));
    sets.emplace_back("lattice 1/64 shifted", lattice(33, 1.0f / 64.0f, 0.25f));
    sets.emplace_back("duplicates", std::vector<glm::vec3>(5000, glm::vec3(0.5f, 0.25f, 2.0f)));
    for (size_t n : {65535u, 65536u, 98303u}) {
        std::vector<glm::vec3> p(n);
        for (auto& v : p) v = {u(rng), u(rng), 0.0f};
        sets.emplace_back("plane " + std::to_string(n), p);
    }
    std::vector<glm::vec3> line(20000), cluster(30000);
    for (size_t i = 0; i < line.size(); ++i) line[i] = {float(i) / 16.0f, 3.0f, -1.0f};
    for (auto& v : cluster) v = glm::vec3(u(rng), u(rng), u(rng)) * 1e-3f;
    cluster[7] = glm::vec3(5.0f, 0.0f, 0.0f);
    sets.emplace_back("line", line);
    sets.emplace_back("cluster + outlier", cluster);
    const std::vector<glm::vec3> queries = {{0.1f, 0.2f, 0.3f}, {2.0f, -1.0f, 0.5f}, {0.0f, 0.0f, 0.0f}};
    for (const auto& [name, targets] : sets) {
        SCOPED_TRACE(name);
        auto device = engine->compute(queries, targets);
        const Strided sq(queries), st(targets);
        auto host = engine->compute(sq.view, st.view);
        ASSERT_TRUE(device.ok()) << device.error().message;
        ASSERT_TRUE(host.ok()) << host.error().message;
        expectSameDirection(device->aToB, host->aToB);
        EXPECT_GE(device->aToB.counters.bits, 1u);
    }
}

// The device reads the caller's arrays in place (an import of their pages)
// where the driver allows it; arrays that start mid-page and the copy that
// serves when imports are off give the same answers.
TEST(IngestPath, ImportedOrCopiedArraysStartingAnywhere) {
    const std::vector<OracleCase> cases = makeOracleCases();
    for (const char* import : {"1", "0"}) {
        Options options = gpuOptions();
        options.tuning->hostImport = import[0] == '1';
        RTHDIST_REQUIRE_ENGINE(engine, options);
        for (size_t k = 5; k < cases.size(); k += 41) {
            const OracleCase& c = cases[k];
            SCOPED_TRACE(c.name + (import[0] == '1' ? " imported" : " copied"));
            // B placed 1..3 points into a larger array: its data starts at
            // an offset of 12-36 bytes from the array's start.
            const size_t shift = 1 + k % 3;
            std::vector<glm::vec3> padded(c.b.size() + shift + 5, glm::vec3(1e9f));
            std::copy(c.b.begin(), c.b.end(), padded.begin() + long(shift));
            auto r = engine->compute(c.a, std::span<const glm::vec3>(padded.data() + shift, c.b.size()));
            ASSERT_TRUE(r.ok()) << r.error().message;
            expectMatchesOracle(c, *r);
        }
    }
}

TEST(IngestPath, FirstNonFinitePointOfEachSetIsNamedAsOnTheHost) {
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    std::vector<glm::vec3> a(10000), b(5000);
    for (size_t i = 0; i < a.size(); ++i) a[i] = glm::vec3(float(i % 97), float(i % 13), float(i) * 1e-3f);
    for (size_t i = 0; i < b.size(); ++i) b[i] = glm::vec3(float(i % 31), 0.5f, float(i) * 2e-3f);
    b[4321].y = std::numeric_limits<float>::infinity();
    b[3000].z = -std::numeric_limits<float>::infinity();
    b[4999].x = std::numeric_limits<float>::quiet_NaN();
    auto device = engine->compute(a, b);
    const Strided sa(a), sb(b);
    auto host = engine->compute(sa.view, sb.view);
    ASSERT_FALSE(device.ok());
    ASSERT_FALSE(host.ok());
    EXPECT_EQ(device.error().code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(device.error().message, host.error().message);
    EXPECT_NE(device.error().message.find("point set B: point 3000 "), std::string::npos)
        << device.error().message;
    a[129].x = std::numeric_limits<float>::quiet_NaN();  // A is checked first
    auto both = engine->compute(a, b);
    ASSERT_FALSE(both.ok());
    EXPECT_NE(both.error().message.find("point set A: point 129 "), std::string::npos)
        << both.error().message;
}

TEST(IngestPath, CoordinatesPastTheFloatSquareRangeAreScaledExactly) {
    // |p| ~ 1e25: squared distances overflow float, so the pair needs the
    // exact power-of-two scale of index_space.hpp (the host path applies it).
    RTHDIST_REQUIRE_ENGINE(engine, gpuOptions());
    const std::vector<OracleCase> cases = makeOracleCases();
    const OracleCase& base = cases[3];
    OracleCase c{base.name + "-times-1e25", base.seed, base.a, base.b};
    for (auto* set : {&c.a, &c.b})
        for (glm::vec3& p : *set) p *= 1e25f;
    auto r = engine->compute(c.a, c.b);
    ASSERT_TRUE(r.ok()) << r.error().message;
    expectMatchesOracle(c, *r);
}

}  // namespace
}  // namespace rthdist::test
