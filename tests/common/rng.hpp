// The test suites' random numbers: one portable generator (std
// distributions differ between standard libraries), fixed seeds.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

namespace rthdist::test {

// Portable generator (std distributions differ between standard libraries).
class Rng {
public:
    explicit Rng(uint64_t seed) : m_state(seed * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull) {}
    uint64_t next() {  // splitmix64
        uint64_t z = (m_state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    size_t index(size_t n) { return size_t(next() % n); }
    double gauss() {
        const double u = std::max(uniform(), 1e-300), v = uniform();
        return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
    }
    glm::dvec3 direction() {
        for (;;) {
            glm::dvec3 d(gauss(), gauss(), gauss());
            const double l = glm::length(d);
            if (l > 1e-9) return d / l;
        }
    }

private:
    uint64_t m_state;
};

}  // namespace rthdist::test
