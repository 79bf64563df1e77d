// Pieces of a pair ordered in space, for the out-of-core route (issue 33;
// design.md §9). Both sets are cut by one grid over the pair's box: cells in
// Morton order are taken into pieces until a piece would hold more points of
// a set than its limit, so a piece is a run of neighbouring cells holding
// points of both sets, and a query meets its nearest targets in its own
// piece unless it lies near the piece's border. A cell with more points of a
// set than the limit is split over several pieces by input order (a
// "shared" cell: such pieces overlap in space; correct, only slower).
//
// Each set is gathered piece after piece, and `input` maps a gathered point
// back. Within a piece (PieceOrder):
//   - kInput: input order, so that a call on a piece breaks ties as a call
//     on the whole set would (the smaller input index first): for callers
//     whose per-point output names each query's nearest point;
//   - kBlocks: blocks in space, each the piece's points in one group of
//     cells (the grid's cells cut into at most 2^kBlockGroupBits groups of
//     consecutive Morton codes: 4 x 4 x 4 cells at the largest grid), the
//     groups in Morton order, input order within a group. A query's
//     nearest target then lies near it in memory as in space, for the read
//     of every query's pair after a call (round one of the out-of-core
//     route: 1.9 s against 2.3-2.4 s in input order on the torus quarter,
//     docs/bench/scale session 13). The pieces and their points are those
//     of kInput.
//
// Threading: partition() runs its passes on `threads` threads (0: all); the
// object is then read-only and may be read from any thread.
// Memory: per set 16 bytes per point (the gathered copy and its input
// indices; 20 with the cells kept) and, while partitioning, 2 more (each
// point's cell in input order, freed at the end); the grid at most
// 2^15 cells (12 bytes and a bit each), 12 bytes per block and, while
// partitioning, 4 bytes per cell and 8 per block for each host thread, and
// while scattering 328 bytes per block for each host thread where blocks
// are at most 2^14 (each block's next 16 points, written a whole cache line
// at a time).
// Limits: each set below 2^32 points (the input indices are 32-bit).
#pragma once

#include <glm/vec3.hpp>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "core/index_space.hpp"
#include "core/uninit_vector.hpp"

namespace rthdist::api {

// The order of a piece's points (above).
enum class PieceOrder { kInput, kBlocks };
// kBlocks: the grid's cells fall into at most 2^kBlockGroupBits groups.
inline constexpr uint32_t kBlockGroupBits = 12;

// Points of each set that one piece may hold (>= 1 each).
struct PieceLimits {
    uint64_t a = 1;
    uint64_t b = 1;
};

class SpatialPieces {
public:
    // The most grid cells a box of boxInPiece or blocksNear may cover.
    static constexpr uint64_t kNearCells = 64;

    // One set, gathered piece after piece.
    struct Set {
        core::UninitVector<glm::vec3> points;  // piece after piece, in the partition's PieceOrder
        core::UninitVector<uint32_t> input;    // the input index of each gathered point
        core::UninitVector<uint32_t> cell;     // the grid cell of each (its Morton code: cellOfScaled),
                                               // when kept (partition's keepCells; else empty: cellAt)
        std::vector<uint64_t> start;           // piece k holds [start[k], start[k + 1])
        std::vector<uint64_t> blockStart;      // block b holds [blockStart[b], blockStart[b + 1])
        [[nodiscard]] std::span<const glm::vec3> piece(size_t k) const {
            return {points.data() + start[k], size_t(start[k + 1] - start[k])};
        }
        [[nodiscard]] uint64_t size(size_t k) const { return start[k + 1] - start[k]; }
    };

    // Cuts sets a and b (scaled by the exact power of two `scale` as searched;
    // each below 2^32 points, at least one point in all) into pieces within
    // `limits`, each piece's points in `order`. `box`: the box of both sets'
    // points as given (not scaled), when the caller has it (the Engine's
    // input check): it spares a pass over the points, and must be exact
    // (each face attained by a point), as largestMagnitude() comes from it.
    // `keepCells`: each gathered point's cell is kept (Set::cell; 4 bytes a
    // point the scatter writes), for callers that ask every point's cell;
    // otherwise cellAt computes the few they ask.
    [[nodiscard]] static SpatialPieces partition(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                 double scale, PieceLimits limits, int threads,
                                                 PieceOrder order = PieceOrder::kInput,
                                                 const core::Bounds* box = nullptr, bool keepCells = true);

    // The partition's passes, ms (for RTHDIST_SUBMIT_TRACE's pieces line).
    struct PassTimes {
        double box = 0.0, keys = 0.0, plan = 0.0, scatter = 0.0;
    };
    [[nodiscard]] const PassTimes& passTimes() const { return m_times; }

    [[nodiscard]] size_t count() const { return m_pieces; }
    [[nodiscard]] const Set& set(int s) const { return s == 0 ? m_a : m_b; }
    [[nodiscard]] uint32_t cellsPerAxis() const { return m_cells; }
    // The largest magnitude of a coordinate of either set as given (not
    // scaled): core::largestMagnitude of both, found in the partition's pass.
    [[nodiscard]] double largestMagnitude() const { return m_magnitude; }
    // The narrowest edge of a grid cell, in search units (scaled).
    [[nodiscard]] double smallestCellEdge() const {
        return 1.0 / std::max({m_inverse[0], m_inverse[1], m_inverse[2]});
    }

    // True only when every point of either set whose scaled coordinates lie
    // within `radius` of q on every axis (q scaled as searched: core::scaled)
    // belongs to piece k: the cells that box touches hold points of piece k
    // only, or none. Exact: the cell of a coordinate is a monotone function
    // of it, computed in double for points and box alike. False for a box of
    // more than kNearCells cells.
    [[nodiscard]] bool boxInPiece(const glm::vec3& q, double radius, uint32_t k) const;
    // The blocks of piece k (Set::blockStart: each set's points of block b
    // lie in one range; both sets share the numbering) that hold every point
    // of piece k whose scaled coordinates lie within `radius` of q on every
    // axis (q scaled as searched), each block once, in `blocks` (cleared
    // first). Exact as boxInPiece. False (and `blocks` undefined) for a box
    // of more than kNearCells cells.
    bool blocksNear(const glm::vec3& q, double radius, uint32_t k, std::vector<uint32_t>& blocks) const;
    // Each piece's box (scaled as searched): the cells that hold its points
    // (of either set), widened by 2^-36 of the grid's magnitude on each axis,
    // so that every point of piece k of either set lies in box k whatever
    // the rounding of its cell. A piece with no points keeps an empty box
    // (lo = +inf, hi = -inf). Looser than the points' own box, found with no
    // pass over the points: a lower bound of the distance to a piece's points
    // for round two, which needs it for a handful of queries.
    [[nodiscard]] std::vector<core::Bounds> pieceBoxes() const;
    // The grid cell (its Morton code) of a point scaled as searched
    // (core::scaled): the cell the partition put it in.
    [[nodiscard]] uint32_t cellOfScaled(const glm::vec3& q) const { return cellOf(glm::dvec3(q)); }
    // The cell of set s's gathered point p: Set::cell's where kept, else
    // computed (~23 ns on the H200 machine's host, where a read costs less).
    [[nodiscard]] uint32_t cellAt(int s, uint64_t p) const {
        const Set& set = this->set(s);
        return set.cell.empty() ? cellOfScaled(core::scaled(set.points[p], m_scale)) : set.cell[p];
    }
    // The same answer, cheaper, for most points of a spread set: true when a
    // box of `radius` (at most half a cell a side) around a point of `cell`
    // (Set::cell) stays within the cells around it, and those hold the
    // points of that cell's piece only, or none (a "solid" cell; each axis's
    // cell moves by at most one). False says nothing: ask boxInPiece.
    // Inline: asked once for every query after round one.
    [[nodiscard]] bool solidAround(uint32_t cell, double radius) const {
        return radius * m_inverse[0] <= 0.5 && radius * m_inverse[1] <= 0.5 && radius * m_inverse[2] <= 0.5 &&
               ((m_solid[cell >> 6] >> (cell & 63u)) & 1u) != 0;
    }

private:
    static constexpr uint32_t kEmpty = UINT32_MAX;       // a cell without points
    static constexpr uint32_t kShared = UINT32_MAX - 1;  // a cell split over several pieces

    // (v - lo) * inverse side: a monotone function of v (as is each
    // rounding), the same for points and boxes; clamped to the grid, without
    // branches (NaN to 0, as `c > 0` is false for it), so that the keys'
    // pass vectorizes. Inline, so that each of the keys pass's clones
    // (spatial_pieces.cpp, cellsOf) compiles it for its own instructions.
    [[nodiscard]] uint32_t axisCell(double v, int axis) const {
        double c = (v - m_lo[axis]) * m_inverse[axis];
        c = c > 0.0 ? c : 0.0;
        const double top = double(m_cells - 1);
        c = c < top ? c : top;
        return uint32_t(c);
    }
    [[nodiscard]] uint32_t cellOf(const glm::dvec3& p) const {
        return core::mortonEncode(axisCell(p.x, 0), axisCell(p.y, 1), axisCell(p.z, 2));
    }
    // fn(cell) for each cell (Morton code) that the box of half-side
    // `radius` around q (scaled) touches, until fn returns false; false then,
    // or when the box covers more than kNearCells cells.
    template <class Fn>
    bool forCellsInBox(const glm::vec3& q, double radius, Fn&& fn) const;

    Set m_a, m_b;
    PassTimes m_times;
    size_t m_pieces = 0;
    uint32_t m_cells = 1;  // per axis (a power of two)
    double m_magnitude = 0.0;
    double m_scale = 1.0;  // the scale the points are searched at
    double m_lo[3] = {0.0, 0.0, 0.0};
    double m_inverse[3] = {1.0, 1.0, 1.0};  // cells per unit on each axis
    std::vector<uint64_t> m_solid;  // a bit per cell: it and its neighbours hold one piece's points, or none
    std::vector<uint32_t> m_owner;  // per cell (Morton code): its piece, kEmpty or kShared
    // Per cell, the blocks holding its points: [first, first + count); per block, its piece.
    std::vector<uint32_t> m_blockFirst, m_blockCount, m_blockPiece;
};

}  // namespace rthdist::api
