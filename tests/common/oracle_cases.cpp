#include "common/oracle_cases.hpp"

#include "core/certificate.hpp"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "common/brute_force.hpp"
#include "common/oracle_memo.hpp"
#include "common/point_shapes.hpp"
#include "common/rng.hpp"
#include "core/search_mutant.hpp"

namespace rthdist::test {
namespace {

using Points = std::vector<glm::vec3>;

Points gaussianBlobs(Rng& r, size_t n, int blobs, double spread, double sigma) {
    std::vector<glm::dvec3> centres(size_t(std::max(blobs, 1)));
    for (glm::dvec3& c : centres) c = glm::dvec3(r.uniform(), r.uniform(), r.uniform()) * spread;
    Points p(n);
    for (glm::vec3& v : p) {
        const glm::dvec3& c = centres[r.index(centres.size())];
        v = glm::vec3(c + sigma * glm::dvec3(r.gauss(), r.gauss(), r.gauss()));
    }
    return p;
}
Points sphere(Rng& r, size_t n, glm::dvec3 centre, double radius) {
    Points p(n);
    for (glm::vec3& v : p) v = glm::vec3(centre + radius * r.direction());
    return p;
}
Points plane(Rng& r, size_t n, glm::dvec3 origin, glm::dvec3 u, glm::dvec3 v) {
    Points p(n);
    for (glm::vec3& x : p) x = glm::vec3(origin + r.uniform() * u + r.uniform() * v);
    return p;
}
Points segment(Rng& r, size_t n, glm::dvec3 from, glm::dvec3 to) {
    Points p(n);
    for (glm::vec3& x : p) x = glm::vec3(from + r.uniform() * (to - from));
    return p;
}
Points translated(const Points& p, glm::dvec3 d) {
    Points out(p.size());
    for (size_t i = 0; i < p.size(); ++i) out[i] = glm::vec3(glm::dvec3(p[i]) + d);
    return out;
}
Points shuffled(Rng& r, Points p) {
    for (size_t i = p.size(); i > 1; --i) std::swap(p[i - 1], p[r.index(i)]);
    return p;
}
double extentOf(const Points& p) {
    glm::vec3 lo = p[0], hi = p[0];
    for (const glm::vec3& v : p) {
        lo = glm::min(lo, v);
        hi = glm::max(hi, v);
    }
    const glm::vec3 e = hi - lo;
    return double(std::max({e.x, e.y, e.z}));
}

// Small sizes dominate; the brute force of the whole list stays cheap.
constexpr size_t kSizes[] = {1, 2, 3, 5, 8, 13, 40, 100, 257, 600, 1000, 2000, 3000};
size_t sizeAt(size_t i) { return kSizes[i % std::size(kSizes)]; }

const glm::dvec3 kAxes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.6, 0.8, 0}, {0.48, 0.6, 0.64}};

class Builder {
public:
    std::vector<OracleCase> cases;
    template <class Fn>
    void family(const std::string& name, int count, Fn&& make) {
        for (int i = 0; i < count; ++i) {
            OracleCase c;
            c.name = name + "_" + std::to_string(i);
            c.seed = uint64_t(cases.size()) * 7919u + 17u;
            Rng r(c.seed);
            make(r, size_t(i), c.a, c.b);
            cases.push_back(std::move(c));
        }
    }
};

}  // namespace

std::vector<OracleCase> makeOracleCases() {
    Builder f;
    f.family("uniform", 40, [](Rng& r, size_t i, Points& a, Points& b) {
        a = uniformBox(r, sizeAt(i), {0, 0, 0}, {1, 1, 1});
        b = uniformBox(r, sizeAt(i * 7 + 3), {0, 0, 0}, {1, 1 + 0.1 * double(i % 4), 1});
    });
    f.family("gaussian", 20, [](Rng& r, size_t i, Points& a, Points& b) {
        a = gaussianBlobs(r, sizeAt(i + 5), int(1 + i % 5), 10.0, 0.5);
        b = gaussianBlobs(r, sizeAt(i * 3 + 8), int(1 + (i / 5) % 4), 10.0, 0.3 + 0.2 * double(i % 3));
    });
    f.family("sphere_shell", 20, [](Rng& r, size_t i, Points& a, Points& b) {
        a = sphere(r, sizeAt(i + 6), {0, 0, 0}, 1.0);
        b = sphere(r, sizeAt(i * 5 + 9), {0.01 * double(i % 3), 0, 0}, 1.0 + 0.05 * double(i % 4));
    });
    f.family("plane", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = plane(r, sizeAt(i + 7), {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
        b = plane(r, sizeAt(i * 2 + 9), {0, 0, 0.02 * double(i % 5)}, {1, 0, 0.1 * double(i % 3)}, {0, 1, 0});
    });
    f.family("overlapping", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = uniformBox(r, sizeAt(i + 8), {0, 0, 0}, {2, 1, 1});
        b = concat(uniformBox(r, sizeAt(i + 10), {0.1, 0.1, 0.1}, {1.9, 0.9, 0.9}),
                   gaussianBlobs(r, sizeAt(i + 4), 2, 1.0, 0.05));
    });
    f.family("partial_overlap", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const double shift = 0.2 + 0.1 * double(i % 7);
        a = uniformBox(r, sizeAt(i + 9), {0, 0, 0}, {1, 1, 1});
        b = uniformBox(r, sizeAt(i + 11), {shift, shift * 0.5, 0}, {1 + shift, 1 + shift * 0.5, 1});
    });
    f.family("nested", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = uniformBox(r, sizeAt(i + 6), {0.45, 0.45, 0.45}, {0.55, 0.55, 0.55});
        b = uniformBox(r, sizeAt(i + 10), {0, 0, 0}, {1, 1, 1});
        if (i % 2) std::swap(a, b);
    });
    f.family("far_apart", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = uniformBox(r, sizeAt(i + 5), {0, 0, 0}, {1, 1, 1});
        b = translated(sphere(r, sizeAt(i + 9), {0, 0, 0}, 0.5),
                       kAxes[i % 5] * std::pow(10.0, 2 + double(i % 3)));
    });
    f.family("far_1e6_cells", 10, [](Rng& r, size_t i, Points& a, Points& b) {
        // A cell is at most half the extent of B, so 5e5 extents >= 1e6 cell widths.
        b = uniformBox(r, sizeAt(i + 7), {0, 0, 0}, {1, 1, 1});
        a = translated(uniformBox(r, sizeAt(i + 4), {0, 0, 0}, {1, 1, 1}), kAxes[i % 5] * 5e5 * extentOf(b));
        if (i % 2) std::swap(a, b);
    });
    f.family("translated_copy", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = sphere(r, sizeAt(i + 8), {0, 0, 0}, 1.0);
        a = concat(a, uniformBox(r, sizeAt(i + 3), {-1, -0.2, -0.2}, {1, 0.2, 0.2}));
        const double frac[] = {0.3, 0.5, 0.7};
        b = translated(a, kAxes[i % 5] * frac[i % 3] * extentOf(a));
    });
    f.family("subset", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        b = gaussianBlobs(r, sizeAt(i + 7), 3, 1.0, 0.2);
        a.clear();
        for (const glm::vec3& p : b) {
            if (r.uniform() < 0.3) a.push_back(p);
        }
        if (a.empty()) a.push_back(b[r.index(b.size())]);
        if (i % 3 == 2) std::swap(a, b);
    });
    f.family("duplicates", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const Points base = uniformBox(r, sizeAt(i + 5), {0, 0, 0}, {1, 1, 1});
        for (size_t k = 0; k < 1 + i % 4; ++k) a = concat(a, base);
        a = shuffled(r, a);
        b = uniformBox(r, sizeAt(i + 6), {0, 0, 0}, {1, 1, 1});
        b = shuffled(r, concat(b, b));
    });
    f.family("one_point", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        a = uniformBox(r, i % 3 == 1 ? sizeAt(i + 8) : 1, {0, 0, 0}, {1, 1, 1});
        b = uniformBox(r, i % 3 == 2 ? sizeAt(i + 9) : 1, {0, 0, 0}, {1, 1, 1});
    });
    f.family("all_identical", 10, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::vec3 p(r.uniform(-5, 5), r.uniform(-5, 5), r.uniform(-5, 5));
        const glm::vec3 q = i % 2 ? p : glm::vec3(r.uniform(-5, 5), r.uniform(-5, 5), r.uniform(-5, 5));
        a.assign(sizeAt(i + 3), p);
        b.assign(sizeAt(i + 6), q);
        if (i % 3 == 0) b.push_back(p + glm::vec3(1, 0, 0));
    });
    f.family("coplanar", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 n = kAxes[i % 5];
        const glm::dvec3 u = glm::normalize(glm::cross(n, glm::dvec3(0.3, 0.2, 0.9)));
        const glm::dvec3 v = glm::cross(n, u);
        a = plane(r, sizeAt(i + 7), {1, 2, 3}, u * 2.0, v);
        b = plane(r, sizeAt(i + 5), {1, 2, 3}, u, v * 2.0);
    });
    f.family("collinear", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 d = kAxes[i % 5];
        a = segment(r, sizeAt(i + 6), {0, 0, 0}, d * 3.0);
        b = segment(r, sizeAt(i + 4), d * 1.0, d * 5.0);
    });
    f.family("counterexample_1d", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        // design.md §3: q = 0.5, t1 = 1.99, t2 = -0.1 (NN 0.6, corner test gives 1.49).
        const double scale = std::pow(10.0, double(int(i % 5) - 2));
        if (i < 10) {
            const glm::dvec3 d = kAxes[i % 5];
            a = {glm::vec3(0.5 * scale * d)};
            b = {glm::vec3(1.99 * scale * d), glm::vec3(-0.1 * scale * d)};
            if (i >= 5) {  // extra targets outside the query's reach, more queries
                b.push_back(glm::vec3(-5.0 * scale * d));
                b.push_back(glm::vec3(7.0 * scale * d));
                a.push_back(glm::vec3(0.45 * scale * d));
            }
        } else {  // 3-D versions: the far corner of the query's cell vs a near point across
            const glm::dvec3 one(1.0);
            a = {glm::vec3(0.5 * scale * one)};
            b = {glm::vec3(1.99 * scale * one), glm::vec3(-0.1 * scale * one),
                 glm::vec3(scale * glm::dvec3(1.99, -0.1, 0.5))};
            b = concat(b, uniformBox(r, 20, glm::dvec3(3) * scale, glm::dvec3(4) * scale));
        }
    });
    f.family("large_offset", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 o(1e7, -1e7 + 3.0 * double(i), 3e6);
        const double extent = std::pow(10.0, double(i % 3));
        a = uniformBox(r, sizeAt(i + 7), o, o + extent);
        b = translated(sphere(r, sizeAt(i + 9), {0, 0, 0}, extent * 0.5), o + 0.5 * extent);
    });
    f.family("lattice_ties", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        const int n = int(2 + i % 6);
        for (int x = 0; x < n; ++x)
            for (int y = 0; y < n; ++y)
                for (int z = 0; z < n; ++z) {
                    a.emplace_back(float(x), float(y), float(z));
                    if ((x + y + z) % 2 == 0 || i % 3 == 0) b.emplace_back(float(x), float(y), float(z));
                }
        if (i % 3 == 0) b = translated(b, {0.5, 0.5, 0.5});
        if (i % 3 == 1) a = shuffled(r, a);
        if (i % 2) std::swap(a, b);
    });
    f.family("heavy_tailed", 15, [](Rng& r, size_t i, Points& a, Points& b) {
        auto cauchy = [&r](size_t n) {
            Points p(n);
            for (glm::vec3& v : p) {
                for (int k = 0; k < 3; ++k) {
                    const double t = std::tan(std::numbers::pi * (r.uniform() - 0.5));
                    v[k] = float(std::clamp(t, -1e4, 1e4));
                }
            }
            return p;
        };
        a = cauchy(sizeAt(i + 8));
        b = i % 2 ? cauchy(sizeAt(i + 10)) : gaussianBlobs(r, sizeAt(i + 10), 8, 100.0, 0.01);
    });
    // The whole float range (issue 15: a crash at 1e-40, wrong pairs for
    // subnormal coordinates, H = 0 for a 0 / 1e-30 / 1e30 mix): subnormal
    // lattices, tiny and huge magnitudes, mixes, coordinates near FLT_MAX
    // (whose differences overflow float).
    f.family("float_range", 18, [](Rng& r, size_t i, Points& a, Points& b) {
        const size_t n = 20 + i * 7;
        auto box = [&r](size_t count, double half) {
            Points p(count);
            for (glm::vec3& v : p)
                for (int k = 0; k < 3; ++k) v[k] = float((2.0 * r.uniform() - 1.0) * half);
            return p;
        };
        switch (i % 6) {
            case 0:  // multiples of the smallest subnormal
                for (size_t k = 0; k < n; ++k) {
                    a.emplace_back(float(r.index(1000)) * 1.4e-45f, float(r.index(1000)) * 1.4e-45f, 0.0f);
                    b.emplace_back(float(r.index(1000)) * 1.4e-45f, 0.0f, float(r.index(1000)) * 1.4e-45f);
                }
                break;
            case 1: a = box(n, 1e-40), b = box(n + 3, 1e-40); break;
            case 2: a = box(n, 1e-30), b = box(n + 3, 1e-30); break;
            case 3:  // 0, 1e-30 and 1e30 together
                a = {{0, 0, 0}, {1e-30f, 0, 0}, {1e30f, 0, 0}, {0, 1.0f, 0}};
                b = {{1e-30f, 0, 0}, {0, 0, 0}, {1e30f, 1.0f, 0}, {0, 0, 1e-30f}};
                for (size_t k = 0; k < n; ++k) a.push_back(a[k % 4] * float(1 + r.index(3)));
                break;
            case 4: a = box(n, 3e38), b = box(n + 3, 3e38); break;
            default: a = box(n, 1e30), b = box(n + 3, 1e30); break;
        }
    });
    f.family("large", 5, [](Rng& r, size_t i, Points& a, Points& b) {
        const size_t na[] = {50000, 20000, 10000, 50000, 30000};
        const size_t nb[] = {500, 5000, 10000, 2000, 3000};
        a = i % 2 ? gaussianBlobs(r, na[i], 20, 1.0, 0.02) : sphere(r, na[i], {0, 0, 0}, 1.0);
        b = i < 3 ? sphere(r, nb[i], {0, 0, 0}, 1.02) : uniformBox(r, nb[i], {-1, -1, -1}, {1, 1, 1});
    });
    return std::move(f.cases);
}

double oracleTolerance(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double h) {
    auto diagonal = [](std::span<const glm::vec3> p) {
        if (p.empty()) return 0.0;
        glm::dvec3 lo(p[0]), hi(p[0]);
        for (const glm::vec3& v : p) {
            lo = glm::min(lo, glm::dvec3(v));
            hi = glm::max(hi, glm::dvec3(v));
        }
        return glm::length(hi - lo);
    };
    return 1e-6 * std::max(diagonal(a), diagonal(b)) + 8.0 * 0x1.0p-24 * std::fabs(h);
}

namespace {

void expectDirected(const char* what, std::span<const glm::vec3> q, std::span<const glm::vec3> t,
                    const Directed& d, double oracle, double tolerance) {
    SCOPED_TRACE(what);
    EXPECT_NEAR(d.distance, oracle, tolerance);
    ASSERT_LT(d.queryIndex, q.size());
    ASSERT_LT(d.targetIndex, t.size());
    EXPECT_EQ(d.queryPoint, glm::dvec3(q[d.queryIndex]));
    EXPECT_EQ(d.targetPoint, glm::dvec3(t[d.targetIndex]));
    const double pair = glm::length(glm::dvec3(q[d.queryIndex]) - glm::dvec3(t[d.targetIndex]));
    EXPECT_NEAR(pair, d.distance, 1e-12 * std::max(1.0, pair)) << "the witness pair does not realize it";
    const std::vector<double> nn = oracle::bruteForceNearest(q.subspan(d.queryIndex, 1), t, 1);
    EXPECT_NEAR(pair, nn[0], tolerance) << "the witness target is not a nearest neighbour";
}

}  // namespace

void expectMatchesOracle(const OracleCase& c, const HausdorffResult& r, bool directedOnly) {
    std::ostringstream trace;
    trace << "case " << c.name << " seed " << c.seed << " |A|=" << c.a.size() << " |B|=" << c.b.size();
    SCOPED_TRACE(trace.str());
    // Memoized: a case is checked against many results of the same pair.
    const double hab = oracle::memoDirected(c.a, c.b).distance;
    const double hba = directedOnly ? 0.0 : oracle::memoDirected(c.b, c.a).distance;
    const double h = std::max(hab, hba);
    // Exact in double (issue 32): every directed value equals the brute
    // force's, and the witness target is a nearest neighbour in double.
    const double tolerance = 0.0;
    // A backend's own result (not through the Engine) keeps its band: why it failed.
    auto why = [&r](bool ab) {
        if (!r.proofMaterial) return std::string();
        return (ab ? r.proofMaterial->aToB : r.proofMaterial->bToA).failure;
    };
    EXPECT_TRUE(r.aToB.certificate.confirmed) << "h(A,B) carries no confirmed certificate: " << why(true);
    if (!directedOnly) {
        EXPECT_TRUE(r.bToA.certificate.confirmed)
            << "h(B,A) carries no confirmed certificate: " << why(false);
    }
    // The backend's own answer was proven: a recomputation on the CPU backend
    // would hide a search that missed a nearer target (only the search
    // mutant's tests expect one).
    if (!core::searchMutant()) {
        EXPECT_FALSE(r.aToB.certificate.recomputed) << r.aToB.certificate.failure;
        EXPECT_FALSE(r.bToA.certificate.recomputed) << r.bToA.certificate.failure;
    }
    expectDirected("h(A,B)", c.a, c.b, r.aToB, hab, tolerance);
    if (!directedOnly) {
        expectDirected("h(B,A)", c.b, c.a, r.bToA, hba, tolerance);
        EXPECT_NEAR(r.hausdorff, h, tolerance);
        EXPECT_EQ(r.hausdorff, std::max(r.aToB.distance, r.bToA.distance));
    } else {
        EXPECT_EQ(r.hausdorff, r.aToB.distance);
    }
}

}  // namespace rthdist::test
