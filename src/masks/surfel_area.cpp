// Surfel areas from the geometry of the dual cube (surfel_area.hpp has the
// definition). Corner k in [0, 8) of the unit cube is (k >> 2, (k >> 1) & 1,
// k & 1), so its neighbour-code bit is 128 >> k.
#include "masks/surfel_area.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <utility>

namespace rthdist::masks::detail {
namespace {

using Triangle = std::array<int, 3>;  // indices into a polygon's vertices

glm::dvec3 cornerPosition(int k) { return glm::dvec3(double(k >> 2), double((k >> 1) & 1), double(k & 1)); }

// The corners (bit k = corner k) the surface cuts off: the selected ones, or
// the unselected ones when more than four are selected.
unsigned minorityCorners(uint8_t code) {
    unsigned set = 0;
    for (int k = 0; k < 8; ++k)
        if (code & (128 >> k)) set |= 1u << k;
    return std::popcount(set) > 4 ? (~set & 0xffu) : set;
}

// Edge-connected groups of `corners` (two corners share an edge when their
// indices differ in one bit), as bit sets.
std::vector<unsigned> edgeConnectedGroups(unsigned corners) {
    std::vector<unsigned> groups;
    unsigned left = corners;
    while (left) {
        unsigned group = 1u << std::countr_zero(left), grown = 0;
        while (grown != group) {
            grown = group;
            for (int k = 0; k < 8; ++k)
                if (group & (1u << k))
                    for (int axis : {1, 2, 4}) group |= (1u << (k ^ axis)) & corners;
        }
        groups.push_back(group);
        left &= ~group;
    }
    return groups;
}

// The polygon cutting `group` off: the midpoints of its outgoing edges, in
// the order the cube's faces join them. On every face the group's corners
// form one run of the face's 4-cycle (a group has at most 4 corners), so a
// face holds 0 or 2 cut edges, and 2 make one side of the polygon.
std::vector<glm::dvec3> cutPolygon(unsigned group) {
    std::map<std::pair<int, int>, int> vertexOfEdge;  // cut edge (low, high corner) -> vertex
    std::vector<glm::dvec3> vertices;
    std::vector<std::vector<int>> sides;  // per vertex, its neighbours on the polygon
    for (int axis : {1, 2, 4}) {
        const int u = axis == 4 ? 2 : 4, v = axis == 1 ? 2 : 1;  // the face's other two axes
        for (int side : {0, axis}) {
            const int cycle[4] = {side, side | u, side | u | v, side | v};
            std::vector<int> cut;
            for (int e = 0; e < 4; ++e) {
                const int p = cycle[e], q = cycle[(e + 1) % 4];
                if (bool(group & (1u << p)) == bool(group & (1u << q))) continue;
                const auto key = std::minmax(p, q);
                auto [it, added] = vertexOfEdge.try_emplace(key, int(vertices.size()));
                if (added) {
                    vertices.push_back(0.5 * (cornerPosition(p) + cornerPosition(q)));
                    sides.emplace_back();
                }
                cut.push_back(it->second);
            }
            if (cut.size() == 2) {
                sides[size_t(cut[0])].push_back(cut[1]);
                sides[size_t(cut[1])].push_back(cut[0]);
            }
        }
    }
    std::vector<glm::dvec3> polygon{vertices[0]};
    for (int previous = -1, at = 0; polygon.size() < vertices.size();) {
        const int next = sides[size_t(at)][0] != previous ? sides[size_t(at)][0] : sides[size_t(at)][1];
        polygon.push_back(vertices[size_t(next)]);
        previous = at;
        at = next;
    }
    return polygon;
}

// Every triangulation of the polygon's vertices first..last (a fan of
// sub-polygons over the triangle on the edge first-last).
std::vector<std::vector<Triangle>> triangulations(int first, int last) {
    if (last - first < 2) return {{}};
    std::vector<std::vector<Triangle>> out;
    for (int apex = first + 1; apex < last; ++apex)
        for (const auto& left : triangulations(first, apex))
            for (const auto& right : triangulations(apex, last)) {
                std::vector<Triangle> t = left;
                t.push_back({first, apex, last});
                t.insert(t.end(), right.begin(), right.end());
                out.push_back(std::move(t));
            }
    return out;
}

glm::dvec3 areaVector(const std::vector<glm::dvec3>& p, const Triangle& t) {
    return 0.5 * glm::cross(p[size_t(t[1])] - p[size_t(t[0])], p[size_t(t[2])] - p[size_t(t[0])]);
}

// The area vectors of the polygon's triangulation of largest area (the first
// of equal ones: they differ only in how they split a planar part).
std::vector<glm::dvec3> largestTriangulation(const std::vector<glm::dvec3>& polygon) {
    std::vector<glm::dvec3> best;
    double bestArea = -1.0;
    for (const auto& t : triangulations(0, int(polygon.size()) - 1)) {
        double area = 0.0;
        for (const Triangle& tri : t) area += glm::length(areaVector(polygon, tri));
        if (area > bestArea + 1e-12) {
            bestArea = area;
            best.clear();
            for (const Triangle& tri : t) best.push_back(areaVector(polygon, tri));
        }
    }
    return best;
}

std::array<std::vector<glm::dvec3>, 256> buildAreaVectors() {
    std::array<std::vector<glm::dvec3>, 256> table;
    for (int code = 1; code < 255; ++code)
        for (unsigned group : edgeConnectedGroups(minorityCorners(uint8_t(code)))) {
            const std::vector<glm::dvec3> piece = largestTriangulation(cutPolygon(group));
            table[size_t(code)].insert(table[size_t(code)].end(), piece.begin(), piece.end());
        }
    return table;
}

}  // namespace

const std::vector<glm::dvec3>& surfelAreaVectors(uint8_t code) {
    static const std::array<std::vector<glm::dvec3>, 256> table = buildAreaVectors();
    return table[code];
}

std::array<double, 256> surfelAreaTable(glm::dvec3 s) {
    std::array<double, 256> areas{};
    for (int code = 0; code < 256; ++code) {
        double sum = 0.0;
        for (const glm::dvec3& n : surfelAreaVectors(uint8_t(code))) {
            const glm::dvec3 m(n.x * s.y * s.z, n.y * s.x * s.z, n.z * s.x * s.y);
            sum += std::sqrt(m.x * m.x + m.y * m.y + m.z * m.z);
        }
        areas[size_t(code)] = sum;
    }
    return areas;
}

}  // namespace rthdist::masks::detail
