// The closest point of a triangle to a point: one definition for C++
// (core/point_triangle.hpp: the CPU backend's search and the tests' brute
// force, in double, and in 113-bit arithmetic for a thin triangle, whose
// normal double would lose: a template over the vector type there) and GLSL
// (the GPU surface search, in the precision the includer chooses), so that
// every backend measures a triangle alike (design.md §11). The subset both
// languages share: vector arithmetic, dot, cross, `out` parameters spelled
// RTHDIST_PT_OUT.
//
// The rule (no tolerance anywhere, so that two evaluations of the same
// inputs agree to the bit):
//   1. The signed areas of the three sub-triangles seen along the normal
//      n = (b - a) x (c - a): sa = n.((c - b) x (p - b)), sb = n.((p - a) x
//      (c - a)), sc = n.((b - a) x (p - a)). When none is negative and their
//      sum is positive, p projects into the triangle, and the closest point
//      is the projection, with barycentric coordinates (sa, sb, sc) / sum
//      (a convex combination, so it is a point of the triangle however thin
//      the triangle is); a weight that is exactly 0 puts it on the opposite
//      edge, computed from that edge's end points, and two weights of 0 give
//      the vertex itself (so a point exactly at a vertex, or on an edge at a
//      dyadic fraction of it, measures exactly 0).
//   2. Otherwise (the projection falls outside, or the triangle has zero area:
//      collinear or repeated vertices, sum 0) the closest point lies on the
//      boundary: the nearest of the three segments ab, bc, ca (the first on a
//      tie), each by the clamped projection t = ((p - s0).(s1 - s0)) / |s1 -
//      s0|^2; a segment of zero length is its end point.
// The value returned is |p - q|^2 of the closest point q returned, computed
// from q (the distance is realized by the reported point).
//
// Range: every product stays finite when the coordinates' differences are
// below 2^250 (degree 4 in them); a triangle whose squared area underflows
// to 0 (edges below ~1e-75) is measured by its edges, which moves the
// closest point by at most the triangle's own size.
#ifndef RTHDIST_POINT_TRIANGLE_H
#define RTHDIST_POINT_TRIANGLE_H

#ifdef __cplusplus
// C++: templates over the vector type (glm::dvec3, or core/point_triangle.cpp's
// wider type for thin triangles); pt_real is its value_type.
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
namespace rthdist::shared {
using glm::cross;
using glm::dot;
#define pt_real typename pt_vec3::value_type
#define RTHDIST_PT_FN template <class pt_vec3> [[nodiscard]] inline
#define RTHDIST_PT_OUT(T) T&
#else
// GLSL: the includer may #define pt_real and pt_vec3 (double, dvec3) first.
#ifndef pt_real
#define pt_real float
#define pt_vec3 vec3
#endif
#define RTHDIST_PT_FN
#define RTHDIST_PT_OUT(T) out T
#endif

// The point of segment [s0, s1] nearest to p, and its parameter t in [0, 1].
RTHDIST_PT_FN pt_vec3 segmentClosestPoint(pt_vec3 p, pt_vec3 s0, pt_vec3 s1, RTHDIST_PT_OUT(pt_real) t) {
    pt_vec3 d = s1 - s0;
    pt_real len2 = dot(d, d);
    pt_real s = dot(p - s0, d);
    if (!(len2 > pt_real(0)) || s <= pt_real(0)) {
        t = pt_real(0);
        return s0;
    }
    if (s >= len2) {
        t = pt_real(1);
        return s1;
    }
    t = s / len2;
    return s0 + d * t;
}

// Step 2 of the rule: the nearest point of the triangle's three edges.
RTHDIST_PT_FN pt_real triangleEdgesClosest(pt_vec3 p, pt_vec3 a, pt_vec3 b, pt_vec3 c,
                                           RTHDIST_PT_OUT(pt_vec3) closest, RTHDIST_PT_OUT(pt_vec3) bary) {
    pt_real t;
    pt_vec3 q = segmentClosestPoint(p, a, b, t);
    pt_vec3 e = p - q;
    pt_real best = dot(e, e);
    closest = q;
    bary = pt_vec3(pt_real(1) - t, t, pt_real(0));

    q = segmentClosestPoint(p, b, c, t);
    e = p - q;
    pt_real d2 = dot(e, e);
    if (d2 < best) {
        best = d2;
        closest = q;
        bary = pt_vec3(pt_real(0), pt_real(1) - t, t);
    }

    q = segmentClosestPoint(p, c, a, t);
    e = p - q;
    d2 = dot(e, e);
    if (d2 < best) {
        best = d2;
        closest = q;
        bary = pt_vec3(t, pt_real(0), pt_real(1) - t);
    }
    return best;
}

// The rule above: returns |p - closest|^2; bary holds closest's barycentric
// coordinates with respect to (a, b, c).
RTHDIST_PT_FN pt_real pointTriangleClosest(pt_vec3 p, pt_vec3 a, pt_vec3 b, pt_vec3 c,
                                           RTHDIST_PT_OUT(pt_vec3) closest, RTHDIST_PT_OUT(pt_vec3) bary) {
    pt_vec3 ab = b - a;
    pt_vec3 ac = c - a;
    pt_vec3 ap = p - a;
    pt_vec3 n = cross(ab, ac);
    pt_real sa = dot(n, cross(c - b, p - b));
    pt_real sb = dot(n, cross(ap, ac));
    pt_real sc = dot(n, cross(ab, ap));
    pt_real sum = sa + sb + sc;
    if (!(sa >= pt_real(0) && sb >= pt_real(0) && sc >= pt_real(0) && sum > pt_real(0))) {
        return triangleEdgesClosest(p, a, b, c, closest, bary);
    }
    bary = pt_vec3(sa / sum, sb / sum, sc / sum);
    if (sb == pt_real(0) && sc == pt_real(0)) {
        closest = a;
    } else if (sa == pt_real(0) && sc == pt_real(0)) {
        closest = b;
    } else if (sa == pt_real(0) && sb == pt_real(0)) {
        closest = c;
    } else if (sa == pt_real(0)) {
        closest = b + (c - b) * bary.z;
    } else if (sb == pt_real(0)) {
        closest = a + ac * bary.z;
    } else if (sc == pt_real(0)) {
        closest = a + ab * bary.y;
    } else {
        closest = a + ab * bary.y + ac * bary.z;
    }
    pt_vec3 e = p - closest;
    return dot(e, e);
}

#undef RTHDIST_PT_FN
#undef RTHDIST_PT_OUT
#ifdef __cplusplus
#undef pt_real
}  // namespace rthdist::shared
#endif
#endif
