// An axis-aligned box of float points, grown point by point or box by box
// (exact: min and max round nothing). Empty: lo = +inf, hi = -inf, which any
// add() replaces. An aggregate: {lo, hi} builds one directly.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <limits>

namespace rthdist::core {

struct FloatBox {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void add(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void add(const FloatBox& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
};

}  // namespace rthdist::core
