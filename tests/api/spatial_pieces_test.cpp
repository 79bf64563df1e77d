// The pieces in space of the out-of-core route (src/api/spatial_pieces.hpp)
// on the host: every point in exactly one piece, input order within a
// piece (or blocks in space: PieceOrder::kBlocks), the limits kept (crowded
// cells split by input order), boxInPiece never true for a box that
// holds a point of another piece, and blocksNear never missing a point of
// its piece in its box.
#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <bit>
#include <limits>
#include <vector>

#include "api/spatial_pieces.hpp"
#include "common/rng.hpp"
#include "core/index_space.hpp"

namespace rthdist::test {
namespace {

using api::PieceLimits;
using api::PieceOrder;
using api::SpatialPieces;

std::vector<glm::vec3> cloud(size_t n, uint64_t seed, float spread, glm::vec3 at = glm::vec3(0.0f)) {
    Rng rng(seed);
    std::vector<glm::vec3> p(n);
    for (glm::vec3& v : p)
        v = at + spread * glm::vec3(float(rng.uniform()), float(rng.uniform()), float(rng.uniform()));
    return p;
}

// Every input point once, in input order within its piece, each piece within the limits.
void expectAPartition(const SpatialPieces& pieces, const std::vector<glm::vec3>* sets[2],
                      PieceLimits limits) {
    const uint64_t limit[2] = {limits.a, limits.b};
    for (int s = 0; s < 2; ++s) {
        const SpatialPieces::Set& set = pieces.set(s);
        ASSERT_EQ(set.start.size(), pieces.count() + 1);
        ASSERT_EQ(set.start.back(), sets[s]->size());
        std::vector<int> seen(sets[s]->size(), 0);
        for (size_t k = 0; k < pieces.count(); ++k) {
            EXPECT_LE(set.size(k), limit[s]) << "set " << s << " piece " << k;
            for (uint64_t g = set.start[k]; g < set.start[k + 1]; ++g) {
                const uint32_t i = set.input[g];
                ASSERT_LT(i, sets[s]->size());
                ++seen[i];
                EXPECT_EQ(set.points[g], (*sets[s])[i]);
                if (g > set.start[k]) EXPECT_LT(set.input[g - 1], i) << "input order within piece " << k;
            }
        }
        EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; })) << "set " << s;
    }
}

TEST(SpatialPieces, EveryPointOnceInInputOrderWithinTheLimits) {
    const std::vector<glm::vec3> a = cloud(5000, 1, 1.0f), b = cloud(3000, 2, 1.0f, glm::vec3(0.3f));
    const std::vector<glm::vec3>* sets[2] = {&a, &b};
    for (const PieceLimits limits : {PieceLimits{400, 400}, PieceLimits{5000, 100}, PieceLimits{1, 1}}) {
        const SpatialPieces pieces = SpatialPieces::partition(a, b, 1.0, limits, 3);
        expectAPartition(pieces, sets, limits);
        EXPECT_GE(pieces.count(),
                  std::max((a.size() + limits.a - 1) / limits.a, (b.size() + limits.b - 1) / limits.b));
    }
}

// Points of one cell past the limit (all at one spot, and a crowded cluster
// beside far strays): split over pieces by input order, each within the limits.
TEST(SpatialPieces, CrowdedCellsAreSplitByInputOrder) {
    const std::vector<glm::vec3> same(1000, glm::vec3(0.25f, -3.0f, 7.0f));
    std::vector<glm::vec3> cluster = cloud(2000, 3, 1e-6f, glm::vec3(5.0f));
    cluster.push_back(glm::vec3(-3000.0f, 0.0f, 0.0f));
    cluster.insert(cluster.begin() + 500, glm::vec3(4000.0f, 1.0f, 2.0f));
    const std::vector<glm::vec3>* sets[2] = {&same, &cluster};
    const PieceLimits limits{128, 300};
    const SpatialPieces pieces = SpatialPieces::partition(same, cluster, 1.0, limits, 2);
    expectAPartition(pieces, sets, limits);
}

// Sets of several host ranges (65,536 points a range and more) with crowded
// cells split over pieces: the same pieces, in the same order, on one
// thread as on four (a range's share of a crowded cell's pieces is found
// from its counts, its points' ranks continue the earlier ranges'), and the
// largest magnitude is core::largestMagnitude's of both sets.
TEST(SpatialPieces, SeveralRangesCutAsOne) {
    std::vector<glm::vec3> a = cloud(200000, 5, 2.0f, glm::vec3(-1.0f));
    for (size_t i = 0; i < a.size(); i += 3) a[i] = glm::vec3(0.5f, 0.25f, -0.75f);  // one crowded cell
    std::vector<glm::vec3> b = cloud(150000, 6, 1e-7f, glm::vec3(0.2f));             // another
    b.push_back(glm::vec3(-40.0f, 3.0f, 9.0f));
    const std::vector<glm::vec3>* sets[2] = {&a, &b};
    for (const PieceLimits limits : {PieceLimits{7001, 9999}, PieceLimits{50000, 3}}) {
        const SpatialPieces one = SpatialPieces::partition(a, b, 0.5, limits, 1);
        const SpatialPieces four = SpatialPieces::partition(a, b, 0.5, limits, 4);
        expectAPartition(four, sets, limits);
        ASSERT_EQ(one.count(), four.count());
        for (int s = 0; s < 2; ++s) {
            EXPECT_EQ(one.set(s).start, four.set(s).start) << "set " << s;
            EXPECT_TRUE(
                std::equal(one.set(s).input.begin(), one.set(s).input.end(), four.set(s).input.begin()))
                << "set " << s;
            EXPECT_TRUE(std::equal(one.set(s).cell.begin(), one.set(s).cell.end(), four.set(s).cell.begin()))
                << "set " << s;
        }
        EXPECT_EQ(four.largestMagnitude(),
                  std::max(core::largestMagnitude(a, 1), core::largestMagnitude(b, 1)));
        EXPECT_EQ(four.largestMagnitude(), 40.0);
    }
}

// The cells' group of kBlocks: the grid's Morton codes cut into at most
// 2^kBlockGroupBits groups.
uint32_t groupOf(const SpatialPieces& pieces, uint32_t cell) {
    const auto cellBits = uint32_t(3 * std::countr_zero(pieces.cellsPerAxis()));
    return cellBits > api::kBlockGroupBits ? cell >> (cellBits - api::kBlockGroupBits) : cell;
}

// kBlocks holds the pieces of kInput, each with the same points, ordered by
// their cells' groups (input order within a group); one thread cuts as four,
// and the cells kept or not change nothing else.
// Sets of 2^15 cells (the largest grid, 8 cells a group) with crowded cells
// shared by pieces, and small ones.
TEST(SpatialPieces, BlocksInSpaceHoldTheSamePieces) {
    std::vector<glm::vec3> a = cloud(300000, 7, 2.0f, glm::vec3(-1.0f));
    for (size_t i = 0; i < a.size(); i += 5) a[i] = glm::vec3(0.5f, 0.25f, -0.75f);  // one crowded cell
    std::vector<glm::vec3> b = cloud(250000, 8, 1.0f);
    b.push_back(glm::vec3(-40.0f, 3.0f, 9.0f));
    const std::vector<glm::vec3> small = cloud(3000, 9, 1.0f, glm::vec3(0.3f));
    struct Case {
        const std::vector<glm::vec3>* a;
        const std::vector<glm::vec3>* b;
        PieceLimits limits;
    };
    for (const Case& c :
         {Case{&a, &b, {30011, 9999}}, Case{&a, &b, {200000, 3}}, Case{&small, &a, {400, 70000}}}) {
        const SpatialPieces input =
            SpatialPieces::partition(*c.a, *c.b, 0.5, c.limits, 4, PieceOrder::kInput);
        const SpatialPieces blocks =
            SpatialPieces::partition(*c.a, *c.b, 0.5, c.limits, 4, PieceOrder::kBlocks);
        const SpatialPieces one = SpatialPieces::partition(*c.a, *c.b, 0.5, c.limits, 1, PieceOrder::kBlocks);
        // Without the cells kept (the scatter's own loop for a run of points).
        const SpatialPieces noCells =
            SpatialPieces::partition(*c.a, *c.b, 0.5, c.limits, 4, PieceOrder::kBlocks, nullptr, false);
        ASSERT_EQ(input.count(), blocks.count());
        for (int s = 0; s < 2; ++s) {
            const SpatialPieces::Set& x = input.set(s);
            const SpatialPieces::Set& y = blocks.set(s);
            ASSERT_EQ(x.start, y.start) << "set " << s;
            EXPECT_TRUE(std::equal(y.input.begin(), y.input.end(), one.set(s).input.begin())) << "set " << s;
            EXPECT_TRUE(noCells.set(s).cell.empty());
            EXPECT_TRUE(std::equal(y.input.begin(), y.input.end(), noCells.set(s).input.begin()))
                << "set " << s;
            EXPECT_TRUE(std::equal(y.points.begin(), y.points.end(), noCells.set(s).points.begin()))
                << "set " << s;
            for (size_t k = 0; k < input.count(); ++k) {
                std::vector<uint32_t> mine(y.input.begin() + ptrdiff_t(y.start[k]),
                                           y.input.begin() + ptrdiff_t(y.start[k + 1]));
                for (uint64_t g = y.start[k]; g < y.start[k + 1]; ++g) {
                    ASSERT_EQ(y.points[g], (s == 0 ? *c.a : *c.b)[y.input[g]]);
                    ASSERT_EQ(y.cell[g], blocks.cellOfScaled(core::scaled(y.points[g], 0.5)));
                    if (g == y.start[k]) continue;
                    const uint32_t before = groupOf(blocks, y.cell[g - 1]), here = groupOf(blocks, y.cell[g]);
                    ASSERT_LE(before, here) << "set " << s << " piece " << k << " at " << g;
                    if (before == here) ASSERT_LT(y.input[g - 1], y.input[g]) << "input order within a group";
                }
                std::sort(mine.begin(), mine.end());
                EXPECT_TRUE(std::equal(mine.begin(), mine.end(), x.input.begin() + ptrdiff_t(x.start[k])))
                    << "set " << s << " piece " << k;
            }
        }
        if (c.a == &a) EXPECT_EQ(blocks.cellsPerAxis(), 32u);  // the largest grid: groups of 8 cells
    }
}

// boxInPiece and solidAround: whenever either says a box lies in piece k,
// no point of another piece (of either set) lies in that box; and they do
// say so for most small boxes around points of a spread cloud.
TEST(SpatialPieces, BoxInPieceHoldsOnlyThatPiecesPoints) {
    const std::vector<glm::vec3> a = cloud(4000, 4, 2.0f, glm::vec3(-1.0f)), b = cloud(4000, 5, 2.0f);
    const double scale = 0.5;  // searched at half size: boxes are in scaled units
    const SpatialPieces pieces = SpatialPieces::partition(a, b, scale, PieceLimits{500, 500}, 2);
    std::vector<uint32_t> pieceOf[2];
    for (int s = 0; s < 2; ++s) {
        pieceOf[s].resize(pieces.set(s).points.size());
        for (size_t k = 0; k < pieces.count(); ++k)
            for (uint64_t g = pieces.set(s).start[k]; g < pieces.set(s).start[k + 1]; ++g)
                pieceOf[s][pieces.set(s).input[g]] = uint32_t(k);
    }
    const std::vector<glm::vec3>* sets[2] = {&a, &b};
    Rng rng(6);
    size_t inside = 0, solid = 0, tried = 0;
    const SpatialPieces::Set& qs = pieces.set(0);
    for (size_t i = 0; i < a.size(); i += 7) {
        const glm::vec3 q = core::scaled(a[i], scale);
        const double radius = 0.002 * double(rng.index(50));
        const uint32_t k = pieceOf[0][i];
        uint64_t g = qs.start[k];
        while (qs.input[g] != i) ++g;
        ++tried;
        const bool inBoxOfK = pieces.boxInPiece(q, radius, k);
        const bool solidAroundIt = pieces.solidAround(qs.cell[g], radius);
        if (!inBoxOfK && !solidAroundIt) continue;
        inside += inBoxOfK ? 1 : 0;
        solid += solidAroundIt ? 1 : 0;
        for (int s = 0; s < 2; ++s)
            for (size_t j = 0; j < sets[s]->size(); ++j) {
                const glm::vec3 p = core::scaled((*sets[s])[j], scale);
                const bool inBox =
                    glm::all(glm::lessThanEqual(glm::abs(glm::dvec3(p) - glm::dvec3(q)), glm::dvec3(radius)));
                if (inBox) ASSERT_EQ(pieceOf[s][j], k) << "set " << s << " point " << j << " query " << i;
            }
    }
    EXPECT_GT(solid, 0u);
    EXPECT_GT(inside, tried / 2);
}

// The pair's box given (as the Engine's input check has it) cuts as the
// box the partition finds itself: the same pieces, points, cells and
// largest magnitude, both orders. Without the cells kept, the same pieces
// and points, and cellAt computes each point's kept cell.
TEST(SpatialPieces, AGivenBoxCutsAsTheSetsOwn) {
    std::vector<glm::vec3> a = cloud(40000, 13, 3.0f, glm::vec3(-2.0f, 0.5f, 7.0f));
    a.push_back(glm::vec3(-40.0f, 1.0f, 2.0f));
    const std::vector<glm::vec3> b = cloud(30000, 14, 1.0f, glm::vec3(0.25f));
    core::Bounds box{glm::dvec3(std::numeric_limits<double>::infinity()),
                     glm::dvec3(-std::numeric_limits<double>::infinity())};
    const std::vector<glm::vec3>* sets[2] = {&a, &b};
    for (const std::vector<glm::vec3>* s : sets)
        for (const glm::vec3& p : *s) {
            box.lo = glm::min(box.lo, glm::dvec3(p));
            box.hi = glm::max(box.hi, glm::dvec3(p));
        }
    for (const PieceOrder order : {PieceOrder::kBlocks, PieceOrder::kInput}) {
        const SpatialPieces own = SpatialPieces::partition(a, b, 0.25, PieceLimits{9000, 8000}, 3, order);
        const SpatialPieces given =
            SpatialPieces::partition(a, b, 0.25, PieceLimits{9000, 8000}, 3, order, &box);
        ASSERT_GT(own.count(), 2u);
        ASSERT_EQ(own.count(), given.count());
        EXPECT_EQ(own.largestMagnitude(), given.largestMagnitude());
        EXPECT_EQ(given.largestMagnitude(), 40.0);
        for (int s = 0; s < 2; ++s) {
            EXPECT_EQ(own.set(s).start, given.set(s).start) << "set " << s;
            EXPECT_EQ(own.set(s).blockStart, given.set(s).blockStart) << "set " << s;
            EXPECT_TRUE(
                std::equal(own.set(s).input.begin(), own.set(s).input.end(), given.set(s).input.begin()));
            EXPECT_TRUE(
                std::equal(own.set(s).cell.begin(), own.set(s).cell.end(), given.set(s).cell.begin()));
        }
        const SpatialPieces bare =
            SpatialPieces::partition(a, b, 0.25, PieceLimits{9000, 8000}, 3, order, &box, false);
        ASSERT_EQ(bare.count(), own.count());
        for (int s = 0; s < 2; ++s) {
            const SpatialPieces::Set& kept = own.set(s);
            EXPECT_TRUE(bare.set(s).cell.empty());
            ASSERT_EQ(kept.cell.size(), kept.points.size());
            EXPECT_EQ(bare.set(s).start, kept.start) << "set " << s;
            EXPECT_EQ(bare.set(s).blockStart, kept.blockStart) << "set " << s;
            EXPECT_TRUE(std::equal(kept.points.begin(), kept.points.end(), bare.set(s).points.begin()));
            EXPECT_TRUE(std::equal(kept.input.begin(), kept.input.end(), bare.set(s).input.begin()));
            for (uint64_t p = 0; p < kept.points.size(); ++p) {
                ASSERT_EQ(bare.cellAt(s, p), kept.cell[p]) << "set " << s << " point " << p;
                ASSERT_EQ(own.cellAt(s, p), kept.cell[p]);
            }
        }
    }
}

// blocksNear: each set's blocks cut it into consecutive ranges, each in one
// piece; the blocks it names for piece k are that piece's, each once, and
// hold every point of piece k (of either set) within the box; it refuses
// boxes of more than kNearCells cells. Both orders, with shared cells (a
// crowded cell over several pieces) and without.
// Each piece's box from the grid's cells holds every point of the piece, of
// either set (crowded cells split over pieces included), and is no larger
// than the cells around them: within a cell's side of the points' own box.
TEST(SpatialPieces, PieceBoxesHoldTheirPoints) {
    std::vector<glm::vec3> a = cloud(40000, 20, 2.0f, glm::vec3(-1.0f));
    for (size_t i = 0; i < a.size(); i += 7) a[i] = glm::vec3(0.5f, 0.25f, -0.75f);  // one crowded cell
    const std::vector<glm::vec3> b = cloud(30000, 21, 1.5f, glm::vec3(-0.5f, 3.0f, 0.0f));
    for (const double scale : {0.5, 1024.0})
        for (const PieceOrder order : {PieceOrder::kBlocks, PieceOrder::kInput}) {
            const SpatialPieces pieces =
                SpatialPieces::partition(a, b, scale, PieceLimits{3000, 2500}, 3, order);
            const std::vector<core::Bounds> boxes = pieces.pieceBoxes();
            ASSERT_EQ(boxes.size(), pieces.count());
            ASSERT_GT(pieces.count(), 20u);
            const double cell =
                2.0 * 4.5 * scale / double(pieces.cellsPerAxis());  // the grid's widest side, twice
            for (size_t k = 0; k < pieces.count(); ++k) {
                core::Bounds own{glm::dvec3(std::numeric_limits<double>::infinity()),
                                 glm::dvec3(-std::numeric_limits<double>::infinity())};
                for (int s = 0; s < 2; ++s)
                    for (const glm::vec3& p : pieces.set(s).piece(k)) {
                        const glm::dvec3 q(core::scaled(p, scale));
                        ASSERT_TRUE(glm::all(glm::lessThanEqual(boxes[k].lo, q)) &&
                                    glm::all(glm::lessThanEqual(q, boxes[k].hi)))
                            << "piece " << k << " set " << s;
                        own.lo = glm::min(own.lo, q);
                        own.hi = glm::max(own.hi, q);
                    }
                if (pieces.set(0).size(k) + pieces.set(1).size(k) == 0) continue;
                const auto widest = [](const glm::dvec3& v) { return std::max({v.x, v.y, v.z}); };
                EXPECT_LT(widest(own.lo - boxes[k].lo), cell) << "piece " << k;
                EXPECT_LT(widest(boxes[k].hi - own.hi), cell) << "piece " << k;
            }
        }
}

TEST(SpatialPieces, BlocksNearHoldEveryPointOfThePieceInTheBox) {
    std::vector<glm::vec3> a = cloud(60000, 10, 2.0f, glm::vec3(-1.0f));
    for (size_t i = 0; i < a.size(); i += 9) a[i] = glm::vec3(0.5f, 0.25f, -0.75f);  // one crowded cell
    const std::vector<glm::vec3> b = cloud(50000, 11, 1.5f, glm::vec3(-0.5f));
    const double scale = 0.5;
    Rng rng(12);
    size_t named = 0, refused = 0;
    for (const PieceOrder order : {PieceOrder::kBlocks, PieceOrder::kInput})
        for (const PieceLimits limits : {PieceLimits{9000, 7000}, PieceLimits{2000, 60000}}) {
            const SpatialPieces pieces = SpatialPieces::partition(a, b, scale, limits, 3, order);
            std::vector<uint32_t> blockPiece;  // each block's piece, from the sets' ranges
            for (int s = 0; s < 2; ++s) {
                const SpatialPieces::Set& set = pieces.set(s);
                ASSERT_GE(set.blockStart.size(), 2u);
                ASSERT_EQ(set.blockStart.front(), 0u);
                ASSERT_EQ(set.blockStart.back(), set.points.size());
                ASSERT_TRUE(std::is_sorted(set.blockStart.begin(), set.blockStart.end()));
                if (s == 1) ASSERT_EQ(set.blockStart.size(), pieces.set(0).blockStart.size());
            }
            // A block's piece: the piece whose range holds its points (blocks of
            // no points in either set are named by no test below).
            blockPiece.assign(pieces.set(0).blockStart.size() - 1, UINT32_MAX);
            for (int s = 0; s < 2; ++s) {
                const SpatialPieces::Set& set = pieces.set(s);
                for (size_t blk = 0; blk + 1 < set.blockStart.size(); ++blk) {
                    if (set.blockStart[blk] == set.blockStart[blk + 1]) continue;
                    const auto k =
                        uint32_t(std::upper_bound(set.start.begin(), set.start.end(), set.blockStart[blk]) -
                                 set.start.begin() - 1);
                    ASSERT_LE(set.blockStart[blk + 1], set.start[k + 1])
                        << "block " << blk << " spans pieces";
                    if (blockPiece[blk] != UINT32_MAX) ASSERT_EQ(blockPiece[blk], k) << "block " << blk;
                    blockPiece[blk] = k;
                }
            }
            std::vector<uint32_t> blocks;
            for (int probe = 0; probe < 300; ++probe) {
                const glm::vec3 q = core::scaled(
                    probe % 3 == 0
                        ? a[rng.index(a.size())]
                        : glm::vec3(float(rng.uniform()), float(rng.uniform()), float(rng.uniform())) * 3.0f -
                              glm::vec3(1.5f),
                    scale);
                const double radius = probe % 10 == 0 ? 0.5 : 0.001 * double(rng.index(40));
                const auto k = uint32_t(rng.index(pieces.count()));
                if (!pieces.blocksNear(q, radius, k, blocks)) {
                    ++refused;
                    continue;
                }
                ++named;
                ASSERT_TRUE(std::is_sorted(blocks.begin(), blocks.end()));
                ASSERT_TRUE(std::adjacent_find(blocks.begin(), blocks.end()) == blocks.end());
                for (const uint32_t blk : blocks)
                    if (blockPiece[blk] != UINT32_MAX) ASSERT_EQ(blockPiece[blk], k) << "block " << blk;
                for (int s = 0; s < 2; ++s) {
                    const SpatialPieces::Set& set = pieces.set(s);
                    for (uint64_t g = set.start[k]; g < set.start[k + 1]; ++g) {
                        const glm::dvec3 p(core::scaled(set.points[g], scale));
                        if (!glm::all(glm::lessThanEqual(glm::abs(p - glm::dvec3(q)), glm::dvec3(radius))))
                            continue;
                        const bool held = std::any_of(blocks.begin(), blocks.end(), [&](uint32_t blk) {
                            return set.blockStart[blk] <= g && g < set.blockStart[blk + 1];
                        });
                        ASSERT_TRUE(held) << "set " << s << " point " << set.input[g] << " piece " << k;
                    }
                }
            }
        }
    EXPECT_GT(named, 1000u);
    EXPECT_GT(refused, 0u);
}

}  // namespace
}  // namespace rthdist::test
