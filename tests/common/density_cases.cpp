#include "common/density_cases.hpp"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>

#include "common/point_shapes.hpp"
#include "common/rng.hpp"
#include "rthdist/io.hpp"

#ifndef RTHDIST_SHARED_DATA_DIR
#define RTHDIST_SHARED_DATA_DIR ""
#endif

namespace rthdist::test {
namespace {

using Points = std::vector<glm::vec3>;

Points cube(Rng& r, size_t n, glm::dvec3 lo, double edge) { return uniformBox(r, n, lo, lo + edge); }
// Radius r(rng) along a uniform direction around the origin.
template <class Radius>
Points radial(Rng& r, size_t n, Radius radius) {
    Points p(n);
    for (glm::vec3& v : p) v = glm::vec3(r.direction() * radius(r));
    return p;
}
double cauchy(Rng& r) { return std::tan(std::numbers::pi * (r.uniform() - 0.5)); }

// 1 mm cubes and the far point 1.7 km away (issue 17's first row).
constexpr double kMm = 1e-3;
const glm::dvec3 kFar(1000.0, 1000.0, 1000.0);

class Builder {
public:
    std::vector<OracleCase> cases;
    template <class Fn>
    void add(const std::string& name, Fn&& make) {
        OracleCase c;
        c.name = "density_" + name;
        c.seed = 1700u + uint64_t(cases.size()) * 7919u;
        Rng r(c.seed);
        make(r, c.a, c.b);
        cases.push_back(std::move(c));
    }
};

// FSite8 (airborne LiDAR, UTM in float32: duplicates, 0.5 m steps in y).
bool loadLidar(Points& red2, Points& red1) {
    const std::string dir = std::string(RTHDIST_SHARED_DATA_DIR) + "/lidar";
    if (!std::filesystem::exists(dir + "/FSite8_red2-utm.ply")) return false;
    auto a = io::loadPoints(dir + "/FSite8_red2-utm.ply");
    auto b = io::loadPoints(dir + "/FSite8_red1-utm.ply");
    if (!a.ok() || !b.ok()) return false;
    red2 = std::move(a.value());
    red1 = std::move(b.value());
    return true;
}

// Indices of the first copy of every distinct point, and for every point the
// position of its distinct point in that list (ascending first index).
struct Distinct {
    std::vector<uint32_t> first;  // ascending
    std::vector<uint32_t> of;     // point -> position in `first`
    Points points;
};
Distinct distinctOf(const Points& p) {
    std::vector<uint32_t> order(p.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    auto less = [&p](uint32_t i, uint32_t j) {
        if (p[i].x != p[j].x) return p[i].x < p[j].x;
        if (p[i].y != p[j].y) return p[i].y < p[j].y;
        if (p[i].z != p[j].z) return p[i].z < p[j].z;
        return i < j;
    };
    std::sort(order.begin(), order.end(), less);
    Distinct d;
    std::vector<uint32_t> groupOf(p.size());  // point -> group's first index
    for (size_t k = 0; k < order.size(); ++k) {
        const uint32_t i = order[k];
        const bool same = k > 0 && p[order[k - 1]] == p[i];
        groupOf[i] = same ? groupOf[order[k - 1]] : i;
        if (!same) d.first.push_back(i);
    }
    std::sort(d.first.begin(), d.first.end());
    std::vector<uint32_t> slot(p.size());
    for (uint32_t s = 0; s < d.first.size(); ++s) slot[d.first[s]] = s;
    d.of.resize(p.size());
    for (size_t i = 0; i < p.size(); ++i) d.of[i] = slot[groupOf[i]];
    for (uint32_t i : d.first) d.points.push_back(p[i]);
    return d;
}

// Per-point brute force over the distinct queries and targets, expanded.
std::vector<oracle::NearestExact> nearestAll(const Points& q, const Points& t) {
    const Distinct dq = distinctOf(q), dt = distinctOf(t);
    const std::vector<oracle::NearestExact> nn = oracle::bruteForceNearestIndexed(dq.points, dt.points);
    std::vector<oracle::NearestExact> out(q.size());
    for (size_t i = 0; i < q.size(); ++i) {
        const oracle::NearestExact& n = nn[dq.of[i]];
        out[i] = {n.distance, dt.first[n.targetIndex]};
    }
    return out;
}

oracle::DirectedExact maxOf(const std::vector<oracle::NearestExact>& nn) {
    oracle::DirectedExact d;
    d.distance = -1.0;
    for (size_t i = 0; i < nn.size(); ++i) {
        if (nn[i].distance > d.distance) d = {nn[i].distance, uint32_t(i), nn[i].targetIndex};
    }
    return d;
}

void expectDirected(const char* what, const Points& q, const Points& t, const Directed& d,
                    const std::vector<oracle::NearestExact>& nn, double oracle, double tolerance) {
    SCOPED_TRACE(what);
    EXPECT_NEAR(d.distance, oracle, tolerance);
    ASSERT_LT(d.queryIndex, q.size());
    ASSERT_LT(d.targetIndex, t.size());
    EXPECT_EQ(d.queryPoint, glm::dvec3(q[d.queryIndex]));
    EXPECT_EQ(d.targetPoint, glm::dvec3(t[d.targetIndex]));
    const double pair = glm::length(glm::dvec3(q[d.queryIndex]) - glm::dvec3(t[d.targetIndex]));
    EXPECT_NEAR(pair, d.distance, 1e-12 * std::max(1.0, pair)) << "the witness pair does not realize it";
    EXPECT_NEAR(pair, nn[d.queryIndex].distance, tolerance)
        << "the witness target is not a nearest neighbour";
}

std::string traceOf(const OracleCase& c) {
    std::ostringstream s;
    s << "case " << c.name << " seed " << c.seed << " |A|=" << c.a.size() << " |B|=" << c.b.size();
    return s.str();
}

}  // namespace

std::vector<OracleCase> makeDensityCases() {
    Builder f;
    const glm::vec3 p(1.5f, -2.25f, 3.125f), q(2.25f, -1.75f, 2.125f);
    // All points identical (a box of zero extent), 200k per set.
    f.add("identical_200k", [&](Rng&, Points& a, Points& b) {
        a.assign(200000, p);
        b.assign(200000, p);
    });
    f.add("identical_apart_200k", [&](Rng&, Points& a, Points& b) {
        a.assign(200000, p);
        b.assign(200000, q);
    });
    f.add("identical_stray_200k", [&](Rng&, Points& a, Points& b) {
        a.assign(200000, p);
        a[123457] = q;
        b.assign(210000, p);
    });
    // Heavy duplication inside a cluster: half of each set is copies of one point.
    f.add("copies_in_cluster", [](Rng& r, Points& a, Points& b) {
        a = cube(r, 8000, {0, 0, 0}, kMm);
        a = concat(a, Points(8000, a[17]));
        b = cube(r, 8000, {0, 0, 0}, kMm);
        b = concat(Points(9000, glm::vec3(0.5 * kMm)), b);
    });
    // A dense cluster and one point 1.7 km away: the cluster is one grid cell.
    f.add("cluster_far_in_a", [](Rng& r, Points& a, Points& b) {
        a = concat(cube(r, 15000, {0, 0, 0}, kMm), {glm::vec3(kFar)});
        b = cube(r, 15000, {0, 0, 0}, kMm);
    });
    f.add("cluster_far_in_b_cluster_at_max", [](Rng& r, Points& a, Points& b) {
        a = cube(r, 15000, kFar, kMm);
        b = concat({glm::vec3(0.0f)}, cube(r, 15000, kFar, kMm));
    });
    f.add("cluster_far_in_both", [](Rng& r, Points& a, Points& b) {
        a = concat(cube(r, 20000, {0, 0, 0}, kMm), {glm::vec3(kFar)});
        b = concat(cube(r, 20000, {0, 0, 0}, kMm), {glm::vec3(kFar)});
    });
    // Near 1000 m the float step is 6e-5 m: 16 values per axis in the 1 mm
    // cube, so most of the cluster's points are copies.
    f.add("cluster_far_in_both_cluster_at_max", [](Rng& r, Points& a, Points& b) {
        a = concat({glm::vec3(0.0f)}, cube(r, 20000, kFar, kMm));
        b = concat(cube(r, 20000, kFar, kMm), {glm::vec3(0.0f)});
    });
    // Long enough for the CPU's parallel refinement (runs of >= 65536 points).
    f.add("cluster_far_70k", [](Rng& r, Points& a, Points& b) {
        a = concat(cube(r, 70000, {0, 0, 0}, kMm), {glm::vec3(kFar)});
        b = concat(cube(r, 2000, {0, 0, 0}, kMm), {glm::vec3(kFar)});
    });
    // Clusters whose densities differ by up to 10^12.
    f.add("densities", [](Rng& r, Points& a, Points& b) {
        const double edge[] = {1e-5, 1e-3, 0.1, 10.0};
        const glm::dvec3 at[] = {{0, 0, 0}, {5, 0, 0}, {0, 5, 0}, {0, 0, 50}};
        const size_t na[] = {6000, 4000, 2000, 500}, nb[] = {5000, 3000, 1500, 400};
        for (int k = 0; k < 4; ++k) {
            a = concat(a, cube(r, na[k], at[k], edge[k]));
            b = concat(b, cube(r, nb[k], at[k] + 0.3 * edge[k], edge[k]));
        }
    });
    f.add("cauchy", [](Rng& r, Points& a, Points& b) {
        auto cloud = [&r](size_t n) {
            Points p(n);
            for (glm::vec3& v : p) v = glm::vec3(cauchy(r), cauchy(r), cauchy(r));
            return p;
        };
        a = cloud(12000);
        b = cloud(12000);
    });
    f.add("cauchy_radii", [](Rng& r, Points& a, Points& b) {
        auto radius = [](Rng& g) { return std::fabs(cauchy(g)); };
        a = radial(r, 12000, radius);
        b = radial(r, 12000, radius);
    });
    f.add("lognormal_radii", [](Rng& r, Points& a, Points& b) {
        auto radius = [](Rng& g) { return std::exp(2.0 * g.gauss()); };
        a = radial(r, 12000, radius);
        b = radial(r, 12000, radius);
    });
    // Everything in one grid cell (a cell is >= 1/256 of the box) but one point.
    f.add("one_cell_plus_one", [](Rng& r, Points& a, Points& b) {
        a = concat(cube(r, 12000, {0, 0, 0}, 1.0), {glm::vec3(400.0f, 400.0f, 400.0f)});
        b = concat(cube(r, 10000, {0, 0, 0}, 1.0), {glm::vec3(400.0f, 400.0f, 401.0f)});
    });
    Points red2, red1;
    if (loadLidar(red2, red1)) {
        // A real scan with stray returns 5 km from the site (two shared).
        f.add("lidar_stray", [&](Rng& r, Points& a, Points& b) {
            glm::dvec3 lo(red2[0]), hi(red2[0]);
            for (const glm::vec3& v : red2)
                lo = glm::min(lo, glm::dvec3(v)), hi = glm::max(hi, glm::dvec3(v));
            const glm::dvec3 centre = 0.5 * (lo + hi);
            Points stray(8);
            for (glm::vec3& s : stray) s = glm::vec3(centre + 5000.0 * r.direction());
            a = red2;
            for (size_t i = 0; i < red1.size(); i += 4) b.push_back(red1[i]);
            for (size_t k = 0; k < stray.size(); ++k) {
                Points& set = k < 5 ? a : b;
                set.insert(set.begin() + ptrdiff_t(r.index(set.size())), stray[k]);
            }
            a.push_back(stray[6]);  // shared with b
            b.push_back(stray[0]);  // shared with a
        });
    } else {
        std::printf("[ note ] density cases: no %s/lidar, the LiDAR case is left out\n",
                    RTHDIST_SHARED_DATA_DIR);
    }
    return std::move(f.cases);
}

DensityReference densityReference(const OracleCase& c) {
    DensityReference ref;
    ref.aNearest = nearestAll(c.a, c.b);
    ref.bNearest = nearestAll(c.b, c.a);
    ref.aToB = maxOf(ref.aNearest);
    ref.bToA = maxOf(ref.bNearest);
    return ref;
}

void expectMatchesDensity(const OracleCase& c, const DensityReference& ref, const HausdorffResult& r,
                          bool directedOnly) {
    SCOPED_TRACE(traceOf(c));
    const double h = directedOnly ? ref.aToB.distance : std::max(ref.aToB.distance, ref.bToA.distance);
    const double tolerance = 0.0;  // exact in double (issue 32)
    expectDirected("h(A,B)", c.a, c.b, r.aToB, ref.aNearest, ref.aToB.distance, tolerance);
    if (directedOnly) {
        EXPECT_EQ(r.hausdorff, r.aToB.distance);
        return;
    }
    expectDirected("h(B,A)", c.b, c.a, r.bToA, ref.bNearest, ref.bToA.distance, tolerance);
    EXPECT_NEAR(r.hausdorff, h, tolerance);
    EXPECT_EQ(r.hausdorff, std::max(r.aToB.distance, r.bToA.distance));
}

void expectPerPointMatchesDensity(const OracleCase& c, const DensityReference& ref,
                                  const HausdorffResult& r) {
    SCOPED_TRACE(traceOf(c));
    const double tolerance = oracleTolerance(
        c.a, c.b, std::max(ref.aToB.distance, r.bNearest.distance.empty() ? 0.0 : ref.bToA.distance));
    auto check = [&](const char* what, const Points& q, const Points& t, const PerPoint& got,
                     const std::vector<oracle::NearestExact>& want) {
        SCOPED_TRACE(what);
        ASSERT_EQ(got.distance.size(), q.size());
        ASSERT_EQ(got.nearest.size(), q.size());
        int failures = 0;
        for (size_t i = 0; i < q.size() && failures < 5; ++i) {
            const uint32_t j = got.nearest[i];
            if (j >= t.size()) {
                ADD_FAILURE() << "query " << i << ": nearest index " << j << " out of range";
                ++failures;
                continue;
            }
            const double pair = glm::length(glm::dvec3(q[i]) - glm::dvec3(t[j]));
            if (!(std::fabs(got.distance[i] - pair) <= 1e-12 * std::max(1.0, pair)) ||
                !(std::fabs(got.distance[i] - want[i].distance) <= tolerance)) {
                ADD_FAILURE() << "query " << i << ": nearest " << j << " at " << got.distance[i] << " (pair "
                              << pair << ") vs brute force " << want[i].targetIndex << " at "
                              << want[i].distance << ", tolerance " << tolerance;
                ++failures;
            }
        }
    };
    check("A->B", c.a, c.b, r.aNearest, ref.aNearest);
    if (!r.bNearest.distance.empty()) check("B->A", c.b, c.a, r.bNearest, ref.bNearest);
}

}  // namespace rthdist::test
