// The GPU route's per-point entries and the slivers (api/surface_slivers.hpp;
// design.md §11, "Per-point distances").
#include "api/surface_slivers.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "api/surface_certify.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "cpu/triangle_bvh.hpp"

namespace rthdist::api {
namespace {

// The float rule's own error on a triangle the per-point entries trust
// (design.md §11, "Per-point distances"), in the frame's units: with the
// frame's rounding (below 2^-18) it stays under kSearchedReach.
constexpr double kRuleErrorBound = 0x1p-17;

// Whether the float rule may measure triangle (a, b, c) (the device's float
// corners, in the frame) farther than kRuleErrorBound from the double rule
// for a query within `reach` of it (frame units). Its signed areas, of
// degree 4, carry absolute errors ~u_f L^3 D (L its longest edge, D the
// query's distance to a corner: at most reach + L); divided by their sum
// |n|^2 they move the closest point by up to u_f L^4 D / |n|^2 along the
// triangle (never past it: a convex combination). Well-shaped triangles
// (|n| ~ L^2) stay near u_f D; a sliver (|n| = L w, w its width) reaches
// its own length once w^2 ~ u_f L D. Flagged (with a factor 4): those past
// the bound, and zero area (n = 0 in float) unless the corners are one
// point. Only triangles nearer than a query's entry can change it, so
// `reach` is the largest entry (in frame units).
bool illConditioned(const glm::vec3& fa, const glm::vec3& fb, const glm::vec3& fc, double reach) {
    const glm::dvec3 a(fa), b(fb), c(fc);
    const double l2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    if (l2 == 0.0) return false;  // one point: its distance is a vertex's
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double n2 = glm::dot(n, n), l = std::sqrt(l2);
    return !(4.0 * 0x1p-24 * l2 * l2 * (reach + l) <= kRuleErrorBound * n2);
}

// The triangles of `surface` whose float corners (in the frame) the float
// rule may mismeasure for queries within `reach` (frame units), in index
// order (the worker pool in chunks).
std::vector<uint32_t> illConditionedTriangles(std::span<const glm::vec3> corners, double reach, int threads) {
    const size_t triangles = corners.size() / 3;
    const size_t chunk = core::balancedChunk(triangles, threads, 1 << 10);
    std::vector<std::vector<uint32_t>> parts((triangles + chunk - 1) / chunk);
    core::parallelChunks(triangles, chunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            if (illConditioned(corners[3 * t], corners[3 * t + 1], corners[3 * t + 2], reach))
                parts[begin / chunk].push_back(uint32_t(t));
        }
    });
    return core::concatenateParts<std::vector<uint32_t>>(parts);
}

// Cells of a 128^3 grid over the flagged triangles' boxes, marked where a
// box meets them (with a margin for rounding): a query whose
// cube of half-side r meets no marked cell lies farther than r from every
// flagged triangle, and skips the BVH (most queries of a scan near the
// surface: their entries are small and slivers rare).
class FlaggedCells {
public:
    FlaggedCells(const MeshView& surface, std::span<const uint32_t> flagged)
        : m_bits(kCells * kCells * kCells / 64) {
        for (const uint32_t t : flagged) {
            for (int k = 0; k < 3; ++k) {
                m_lo = glm::min(m_lo, surface.corner(t, k));
                m_hi = glm::max(m_hi, surface.corner(t, k));
            }
        }
        const glm::dvec3 extent = m_hi - m_lo;
        for (int a = 0; a < 3; ++a) m_inverse[a] = extent[a] > 0.0 ? double(kCells) / extent[a] : 0.0;
        for (const uint32_t t : flagged) {
            const glm::dvec3 a = surface.corner(t, 0), b = surface.corner(t, 1), c = surface.corner(t, 2);
            const Range r = rangeOf(glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c));
            for (int x = r.lo.x; x <= r.hi.x; ++x)
                for (int y = r.lo.y; y <= r.hi.y; ++y)
                    for (int z = r.lo.z; z <= r.hi.z; ++z) {
                        const size_t i = (size_t(x) * kCells + size_t(y)) * kCells + size_t(z);
                        m_bits[i / 64] |= uint64_t(1) << (i % 64);
                    }
        }
    }
    // Whether the cube of half-side `r` around p meets a marked cell (true
    // where it spans more than kMostCells cells: the BVH decides).
    [[nodiscard]] bool near(const glm::dvec3& p, double r) const {
        const glm::dvec3 lo = p - r, hi = p + r;
        if (lo.x > m_hi.x || lo.y > m_hi.y || lo.z > m_hi.z || hi.x < m_lo.x || hi.y < m_lo.y ||
            hi.z < m_lo.z)
            return false;
        const Range c = rangeOf(lo, hi);
        if (uint64_t(c.hi.x - c.lo.x + 1) * uint64_t(c.hi.y - c.lo.y + 1) * uint64_t(c.hi.z - c.lo.z + 1) >
            kMostCells)
            return true;
        for (int x = c.lo.x; x <= c.hi.x; ++x)
            for (int y = c.lo.y; y <= c.hi.y; ++y)
                for (int z = c.lo.z; z <= c.hi.z; ++z) {
                    const size_t i = (size_t(x) * kCells + size_t(y)) * kCells + size_t(z);
                    if ((m_bits[i / 64] >> (i % 64)) & 1u) return true;
                }
        return false;
    }

private:
    static constexpr int kCells = 128;
    static constexpr uint64_t kMostCells = 64;
    struct Range {
        glm::ivec3 lo, hi;
    };
    [[nodiscard]] Range rangeOf(const glm::dvec3& lo, const glm::dvec3& hi) const {
        Range r;
        for (int a = 0; a < 3; ++a) {
            // (A margin of 2^-20 of a cell either way for the rounding of the products.)
            const double from = std::floor((lo[a] - m_lo[a]) * m_inverse[a] - 0x1p-20);
            const double to = std::floor((hi[a] - m_lo[a]) * m_inverse[a] + 0x1p-20);
            r.lo[a] = int(std::clamp(from, 0.0, double(kCells - 1)));
            r.hi[a] = int(std::clamp(to, 0.0, double(kCells - 1)));
        }
        return r;
    }
    glm::dvec3 m_lo{std::numeric_limits<double>::infinity()}, m_hi{-std::numeric_limits<double>::infinity()};
    glm::dvec3 m_inverse{0.0};
    std::vector<uint64_t> m_bits;
};

// Per-point entries after the proof: a query whose cube of half-side its
// entry (plus the BVH's rounding slack) meets a flagged triangle's cell
// finds its nearest `flagged` triangle (those the float rule may
// mismeasure) in double by the CPU backend's BVH search over them alone,
// and takes it where it is nearer than its entry (or as near with a
// smaller index). The
// others' entries keep the float search's triangle, within its bound.
void measureIllConditioned(const PointView& points, const MeshView& surface,
                           std::span<const uint32_t> flagged, double magnitude, int threads,
                           SurfacePerPoint& entries) {
    const FlaggedCells cells(surface, flagged);
    std::vector<uint32_t> indices;
    indices.reserve(3 * flagged.size());
    for (const uint32_t t : flagged) {
        for (size_t k = 0; k < 3; ++k) indices.push_back(surface.indices[3 * size_t(t) + k]);
    }
    const cpu::TriangleBvh tree(MeshView{surface.vertices, indices}, threads);
    const double slack = core::closestSlack(magnitude);
    core::parallelChunks(points.count, core::balancedChunk(points.count, threads), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t q = begin; q < end; ++q) {
                                 const double entry = entries.distance[q];
                                 if (!(entry > 0.0)) continue;  // on the surface: nothing is nearer
                                 const glm::dvec3 p = points.at(q);
                                 if (!cells.near(p, entry + slack)) continue;
                                 // The nearest flagged triangle (the smallest index on a tie:
                                 // the sub-mesh keeps `flagged`'s ascending order).
                                 const cpu::NearestTriangle hit = tree.nearest(p, slack);
                                 const uint32_t t = flagged[hit.triangle];
                                 if (hit.distance2 > entry * entry ||
                                     (hit.distance2 == entry * entry && t >= entries.triangle[q]))
                                     continue;
                                 entries.distance[q] = std::sqrt(hit.distance2);
                                 entries.triangle[q] = t;
                                 if (!entries.closest.empty()) {
                                     entries.closest[q] = hit.point;
                                     entries.barycentric[q] = hit.barycentric;
                                 }
                             }
                         });
}

}  // namespace

uint64_t measureSlivers(const PointView& points, const MeshView& surface, std::span<const glm::vec3> corners,
                        double scale, double hausdorff, double magnitude, int threads,
                        SurfacePerPoint& entries) {
    // Every entry lies within the tolerance above h.
    const double reach = (hausdorff + entries.tolerance) * scale;
    const std::vector<uint32_t> flagged = illConditionedTriangles(corners, reach, threads);
    if (!flagged.empty()) measureIllConditioned(points, surface, flagged, magnitude, threads, entries);
    return flagged.size();
}

}  // namespace rthdist::api
