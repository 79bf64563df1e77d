#include "core/packed_float_scan.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace rthdist::core {

namespace {

using V4 = float __attribute__((vector_size(16)));
using M4 = int __attribute__((vector_size(16)));

V4 splat(float x) { return V4{x, x, x, x}; }

}  // namespace

PackedScan scanPackedFloats(const float* xyz, size_t count, const glm::vec3& lo, const glm::vec3& hi) {
    // Four points are three vectors: (x0 y0 z0 x1) (y1 z1 x2 y2) (z2 x3 y3 z3);
    // vector k's lane j holds axis (4k + j) % 3, so the box to test and the
    // running minima and maxima are kept in that rotation.
    const V4 testLo[3] = {V4{lo.x, lo.y, lo.z, lo.x}, V4{lo.y, lo.z, lo.x, lo.y}, V4{lo.z, lo.x, lo.y, lo.z}};
    const V4 testHi[3] = {V4{hi.x, hi.y, hi.z, hi.x}, V4{hi.y, hi.z, hi.x, hi.y}, V4{hi.z, hi.x, hi.y, hi.z}};
    constexpr float kInf = std::numeric_limits<float>::infinity();
    V4 mn[3] = {splat(kInf), splat(kInf), splat(kInf)}, mx[3] = {splat(-kInf), splat(-kInf), splat(-kInf)};
    M4 out = {0, 0, 0, 0}, bad = {0, 0, 0, 0};
    const V4 zero = splat(0.0f);
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
        for (int k = 0; k < 3; ++k) {
            V4 v;
            std::memcpy(&v, xyz + 3 * i + 4 * k, sizeof(v));
            mn[k] = v < mn[k] ? v : mn[k];
            mx[k] = v > mx[k] ? v : mx[k];
            out |= (v < testLo[k]) | (v > testHi[k]);
            bad |= (v - v) != zero;  // 0 for finite values, NaN otherwise
        }
    }
    PackedScan s;
    float boxLo[3], boxHi[3];
    for (int axis = 0; axis < 3; ++axis) {
        boxLo[axis] = kInf;
        boxHi[axis] = -kInf;
    }
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 4; ++j) {
            const int axis = (4 * k + j) % 3;
            boxLo[axis] = mn[k][j] < boxLo[axis] ? mn[k][j] : boxLo[axis];
            boxHi[axis] = mx[k][j] > boxHi[axis] ? mx[k][j] : boxHi[axis];
        }
    bool outside = false, nonFinite = false;
    for (int j = 0; j < 4; ++j) {
        outside |= out[j] != 0;
        nonFinite |= bad[j] != 0;
    }
    for (; i < count; ++i)
        for (int axis = 0; axis < 3; ++axis) {
            const float v = xyz[3 * i + axis];
            boxLo[axis] = v < boxLo[axis] ? v : boxLo[axis];
            boxHi[axis] = v > boxHi[axis] ? v : boxHi[axis];
            outside |= v < lo[axis] || v > hi[axis];
            nonFinite |= !std::isfinite(v);
        }
    s.box.lo = glm::vec3(boxLo[0], boxLo[1], boxLo[2]);
    s.box.hi = glm::vec3(boxHi[0], boxHi[1], boxHi[2]);
    s.outside = outside;
    s.nonFinite = nonFinite;
    return s;
}

}  // namespace rthdist::core
