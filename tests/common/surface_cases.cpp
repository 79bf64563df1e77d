#include "common/surface_cases.hpp"

#include <cmath>

#include "common/rng.hpp"

namespace rthdist::test {
namespace {

uint32_t addVertex(SurfaceCase& c, const glm::dvec3& v) {
    c.vertices.push_back(v);
    return uint32_t(c.vertices.size() - 1);
}

void addTriangle(SurfaceCase& c, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& d) {
    const uint32_t i = addVertex(c, a), j = addVertex(c, b), k = addVertex(c, d);
    c.indices.insert(c.indices.end(), {i, j, k});
}

glm::dvec3 randomIn(Rng& rng, const glm::dvec3& lo, const glm::dvec3& hi) {
    return {rng.uniform(lo.x, hi.x), rng.uniform(lo.y, hi.y), rng.uniform(lo.z, hi.z)};
}

void randomQueries(SurfaceCase& c, Rng& rng, size_t n, const glm::dvec3& lo, const glm::dvec3& hi) {
    for (size_t i = 0; i < n; ++i) c.queries.push_back(randomIn(rng, lo, hi));
}

SurfaceCase randomSoup(uint64_t seed, size_t triangles, size_t queries) {
    SurfaceCase c{"random_soup_" + std::to_string(triangles), seed, {}, {}, {}};
    Rng rng(seed);
    for (size_t t = 0; t < triangles; ++t) {
        const glm::dvec3 a = randomIn(rng, glm::dvec3(0.0), glm::dvec3(1.0));
        const double size = 0.01 + 0.2 * rng.uniform();
        addTriangle(c, a, a + rng.direction() * size, a + rng.direction() * size);
    }
    randomQueries(c, rng, queries, glm::dvec3(-0.5), glm::dvec3(1.5));
    return c;
}

// Long thin triangles: the third vertex 1e-3 .. 1e-15 (relative) off the
// line of the first two, or between them on it to the last bit.
SurfaceCase slivers(uint64_t seed) {
    SurfaceCase c{"slivers", seed, {}, {}, {}};
    Rng rng(seed);
    for (int t = 0; t < 200; ++t) {
        const glm::dvec3 a = randomIn(rng, glm::dvec3(0.0), glm::dvec3(1.0));
        const glm::dvec3 b = a + rng.direction() * (0.1 + rng.uniform());
        const double off = std::pow(10.0, -3.0 - 12.0 * rng.uniform());
        const glm::dvec3 mid = a + (b - a) * rng.uniform();
        addTriangle(c, a, b, mid + rng.direction() * off);
    }
    randomQueries(c, rng, 400, glm::dvec3(-0.2), glm::dvec3(1.4));
    // Queries right at the slivers: near their vertices and their long edges.
    for (size_t t = 0; t < 200; t += 3) {
        const glm::dvec3& a = c.vertices[c.indices[3 * t]];
        const glm::dvec3& b = c.vertices[c.indices[3 * t + 1]];
        c.queries.push_back(a + (b - a) * 0.37 + rng.direction() * 1e-9);
        c.queries.push_back(c.vertices[c.indices[3 * t + 2]]);
    }
    return c;
}

// Zero area: collinear (the third vertex at the first two's midpoint,
// exactly), a repeated vertex, all three vertices one point; among ordinary
// triangles, with queries all around.
SurfaceCase zeroArea(uint64_t seed) {
    SurfaceCase c{"zero_area", seed, {}, {}, {}};
    Rng rng(seed);
    for (int t = 0; t < 150; ++t) {
        const glm::dvec3 a = randomIn(rng, glm::dvec3(0.0), glm::dvec3(1.0));
        const glm::dvec3 b = a + rng.direction() * 0.2;
        switch (t % 4) {
            case 0: addTriangle(c, a, b, (a + b) * 0.5); break;
            case 1: addTriangle(c, a, a, b); break;
            case 2: addTriangle(c, a, a, a); break;
            default: addTriangle(c, a, b, a + rng.direction() * 0.2); break;
        }
    }
    randomQueries(c, rng, 500, glm::dvec3(-0.3), glm::dvec3(1.3));
    return c;
}

// The same triangle many times (shared indices and copied coordinates):
// every query ties, the smallest triangle index must win.
SurfaceCase duplicates(uint64_t seed) {
    SurfaceCase c{"duplicates", seed, {}, {}, {}};
    Rng rng(seed);
    for (int k = 0; k < 20; ++k) {
        const glm::dvec3 a = randomIn(rng, glm::dvec3(0.0), glm::dvec3(1.0));
        const glm::dvec3 b = a + rng.direction() * 0.3, d = a + rng.direction() * 0.3;
        addTriangle(c, a, b, d);
        const uint32_t first = uint32_t(c.indices.size() - 3);
        for (int copy = 0; copy < 6; ++copy) {
            if (copy % 2 == 0) {
                c.indices.insert(c.indices.end(),
                                 {c.indices[first], c.indices[first + 1], c.indices[first + 2]});
            } else {
                addTriangle(c, a, b, d);
            }
        }
    }
    randomQueries(c, rng, 400, glm::dvec3(-0.5), glm::dvec3(1.5));
    return c;
}

// Queries at vertices, at dyadic points of edges and faces of a height
// field with dyadic coordinates: every distance is exactly 0.
SurfaceCase onSurface(uint64_t seed) {
    SurfaceCase c = heightField(seed, 8, 8.0);
    c.name = "on_surface";
    Rng rng(seed + 1);
    for (size_t t = 0; t < c.indices.size() / 3; ++t) {
        const glm::dvec3& a = c.vertices[c.indices[3 * t]];
        const glm::dvec3& b = c.vertices[c.indices[3 * t + 1]];
        const glm::dvec3& d = c.vertices[c.indices[3 * t + 2]];
        c.queries.push_back(a);
        c.queries.push_back(a + (b - a) * 0.25);
        c.queries.push_back(b + (d - b) * 0.5);
        c.queries.push_back(a + (b - a) * 0.25 + (d - a) * 0.5);
    }
    return c;
}

SurfaceCase shifted(SurfaceCase c, const std::string& name, const glm::dvec3& by) {
    c.name = name;
    for (glm::dvec3& v : c.vertices) v += by;
    for (glm::dvec3& q : c.queries) q += by;
    return c;
}

}  // namespace

SurfaceCase heightField(uint64_t seed, int n, double size) {
    SurfaceCase c{"height_field", seed, {}, {}, {}};
    Rng rng(seed);
    const double step = size / n;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            // Heights on a 1/64 grid: the vertices, edges and faces stay dyadic.
            const double h = std::round(64.0 * step * rng.uniform(-1.0, 1.0)) / 64.0;
            c.vertices.emplace_back(i * step, j * step, h);
        }
    }
    auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            c.indices.insert(c.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            c.indices.insert(c.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    }
    return c;
}

std::vector<SurfaceCase> makeSurfaceCases() {
    std::vector<SurfaceCase> cases;
    cases.push_back(randomSoup(3401, 300, 600));
    cases.push_back(randomSoup(3402, 4000, 1500));
    {
        SurfaceCase field = heightField(3403, 24, 12.0);
        Rng rng(3403);
        randomQueries(field, rng, 800, glm::dvec3(-2.0, -2.0, -3.0), glm::dvec3(14.0, 14.0, 3.0));
        cases.push_back(field);
    }
    cases.push_back(slivers(3404));
    cases.push_back(zeroArea(3405));
    cases.push_back(duplicates(3406));
    cases.push_back(onSurface(3407));
    {
        SurfaceCase far = randomSoup(3408, 500, 0);
        far.name = "far_apart";
        Rng rng(3408);
        randomQueries(far, rng, 300, glm::dvec3(1e4), glm::dvec3(1e4 + 3.0));
        cases.push_back(far);
    }
    {
        SurfaceCase field = heightField(3409, 16, 200.0);
        Rng rng(3409);
        randomQueries(field, rng, 600, glm::dvec3(-5.0, -5.0, -20.0), glm::dvec3(205.0, 205.0, 20.0));
        cases.push_back(shifted(field, "georeferenced_utm", glm::dvec3(512345.25, 5412345.5, 250.0)));
    }
    cases.push_back(
        shifted(onSurface(3410), "georeferenced_on_surface", glm::dvec3(512000.0, 5412000.0, 0.0)));
    return cases;
}

}  // namespace rthdist::test
