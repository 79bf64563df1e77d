#include "cpu/triangle_bvh.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/point_triangle.hpp"

namespace rthdist::cpu {
namespace {

double boxDistance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

// The squared distance a box must exceed to be skipped: (best + slack)^2,
// infinite while nothing was measured.
double pruneBound2(double best2, double slack) {
    if (!std::isfinite(best2)) return std::numeric_limits<double>::infinity();
    const double bound = std::sqrt(best2) + slack;
    return bound * bound;
}

}  // namespace

TriangleBvh::TriangleBvh(const MeshView& mesh) {
    const size_t n = mesh.triangleCount();
    std::vector<glm::dvec3> lo(n), hi(n), centre(n);
    std::vector<glm::dvec3> corners(3 * n);
    for (size_t t = 0; t < n; ++t) {
        for (int k = 0; k < 3; ++k) corners[3 * t + size_t(k)] = mesh.corner(t, k);
        const glm::dvec3* c = &corners[3 * t];
        lo[t] = glm::min(glm::min(c[0], c[1]), c[2]);
        hi[t] = glm::max(glm::max(c[0], c[1]), c[2]);
        centre[t] = (lo[t] + hi[t]) * 0.5;
    }
    m_original.resize(n);
    std::iota(m_original.begin(), m_original.end(), 0u);
    build(lo, hi, centre);
    m_corners.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        for (size_t k = 0; k < 3; ++k) m_corners[3 * i + k] = corners[3 * size_t(m_original[i]) + k];
    }
}

void TriangleBvh::build(const std::vector<glm::dvec3>& lo, const std::vector<glm::dvec3>& hi,
                        const std::vector<glm::dvec3>& centre) {
    const auto n = uint32_t(m_original.size());
    m_nodes.reserve(std::max<size_t>(n, 1));  // leaves hold 2..kLeafTriangles: fewer nodes than triangles
    m_nodes.push_back(Node{{}, {}, 0, n});
    std::vector<uint32_t> pending{0};
    while (!pending.empty()) {
        const uint32_t at = pending.back();
        pending.pop_back();
        const uint32_t first = m_nodes[at].first;
        const uint32_t count = m_nodes[at].count;
        glm::dvec3 boxLo(std::numeric_limits<double>::infinity()), boxHi(-boxLo);
        glm::dvec3 cLo = boxLo, cHi = boxHi;
        for (uint32_t i = first; i < first + count; ++i) {
            const uint32_t t = m_original[i];
            boxLo = glm::min(boxLo, lo[t]);
            boxHi = glm::max(boxHi, hi[t]);
            cLo = glm::min(cLo, centre[t]);
            cHi = glm::max(cHi, centre[t]);
        }
        m_nodes[at].lo = boxLo;
        m_nodes[at].hi = boxHi;
        if (count <= kLeafTriangles) continue;
        const glm::dvec3 spread = cHi - cLo;
        const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
        const uint32_t half = count / 2;
        // Ties by triangle index: the tree does not depend on the sort's whims.
        std::nth_element(m_original.begin() + first, m_original.begin() + first + half,
                         m_original.begin() + first + count, [&](uint32_t x, uint32_t y) {
                             return centre[x][axis] < centre[y][axis] ||
                                    (centre[x][axis] == centre[y][axis] && x < y);
                         });
        const auto left = uint32_t(m_nodes.size());
        m_nodes[at].first = left;
        m_nodes[at].count = 0;
        m_nodes.push_back(Node{{}, {}, first, half});
        m_nodes.push_back(Node{{}, {}, first + half, count - half});
        pending.push_back(left);
        pending.push_back(left + 1);
    }
}

NearestTriangle TriangleBvh::nearest(const glm::dvec3& p, double slack, double stopBelow2) const {
    NearestTriangle best;
    best.distance2 = std::numeric_limits<double>::infinity();
    double bound2 = best.distance2;
    // Balanced tree: depth <= log2(2^32) + 2, at most one entry per level waits.
    struct Entry {
        uint32_t node;
        double distance2;
    };
    std::array<Entry, 80> stack;
    size_t top = 0;
    stack[top++] = {0, boxDistance2(p, m_nodes[0].lo, m_nodes[0].hi)};
    ++best.nodesVisited;
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.distance2 > bound2) continue;
        const Node& node = m_nodes[e.node];
        if (node.count > 0) {
            for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                const glm::dvec3* c = &m_corners[3 * size_t(i)];
                const core::TriangleClosest r = core::closestOnTriangle(p, c[0], c[1], c[2]);
                ++best.trianglesTested;
                const uint32_t t = m_original[i];
                if (r.distance2 < best.distance2 || (r.distance2 == best.distance2 && t < best.triangle)) {
                    best.distance2 = r.distance2;
                    best.triangle = t;
                    best.point = r.point;
                    best.barycentric = r.barycentric;
                    bound2 = pruneBound2(best.distance2, slack);
                    if (best.distance2 < stopBelow2) {
                        best.dominated = true;
                        return best;
                    }
                }
            }
            continue;
        }
        const Node& l = m_nodes[node.first];
        const Node& r = m_nodes[node.first + 1];
        const double dl = boxDistance2(p, l.lo, l.hi);
        const double dr = boxDistance2(p, r.lo, r.hi);
        best.nodesVisited += 2;
        // Nearer child on top of the stack, visited first.
        const bool leftFirst = dl <= dr;
        const Entry nearE{leftFirst ? node.first : node.first + 1, leftFirst ? dl : dr};
        const Entry farE{leftFirst ? node.first + 1 : node.first, leftFirst ? dr : dl};
        if (farE.distance2 <= bound2) stack[top++] = farE;
        if (nearE.distance2 <= bound2) stack[top++] = nearE;
    }
    return best;
}

size_t TriangleBvh::hostBytes() const {
    return m_nodes.capacity() * sizeof(Node) + m_corners.capacity() * sizeof(glm::dvec3) +
           m_original.capacity() * sizeof(uint32_t);
}

}  // namespace rthdist::cpu
