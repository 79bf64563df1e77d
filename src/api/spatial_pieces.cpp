#include "api/spatial_pieces.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "core/index_space.hpp"
#include "core/parallel.hpp"
#include "core/sanitizers.hpp"
#include "core/stopwatch.hpp"
#include "core/vector_clones.hpp"

#if defined(__SSE2__) && !defined(RTHDIST_UNDER_SANITIZER)
#include <emmintrin.h>
#define RTHDIST_STREAMING_STORES 1
#endif

namespace rthdist::api {

namespace {

using Span = std::span<const glm::vec3>;

// keys[i]: the cell of points[i] scaled as searched, i < n. A loop without
// branches or stores that alias, which the compiler vectorizes: 3x faster
// for AVX-512 than for the baseline (RTHDIST_VECTOR_CLONES), and the same
// cells (SpatialPieces::cellOfScaled, as boxInPiece's).
RTHDIST_VECTOR_CLONES void cellsOf(const SpatialPieces& pieces, const glm::vec3* points, double scale,
                                   size_t n, uint32_t* keys) {
    for (size_t i = 0; i < n; ++i) keys[i] = pieces.cellOfScaled(core::scaled(points[i], scale));
}

// Cells per axis: about 16 points a cell over both sets, 2 to 32 a side
// (at most 2^15 cells: a cell's Morton code fits the 16 bits the keys pass
// stores for each point). Both passes over the points look up a table of
// every cell at random (each host thread's counts, then each cell's block),
// so the grid's size is paid per point: 128 a side cost the H200 machine's
// 32 threads 2.6 s of cache misses on 700M points, and 32 instead of 64 (a
// 128 KiB table in place of 1 MiB) took the torus quarter's partition on
// the 32-core x2 host from 947-995 to 791-798 ms, its first floors as
// good (docs/bench/scale, session 19). 16 a side lowered B's floor on a
// 30M x 40M torus (2 cores). Pieces are a handful, so cells of 1/32 of the
// box cut them finely enough, and a query's best is far below a cell.
uint32_t cellsPerAxisFor(uint64_t points) {
    const double side = std::cbrt(double(points) / 16.0);
    uint32_t cells = 2;
    while (cells < 32 && double(cells) < side) cells *= 2;
    return cells;
}
static_assert(32 * 32 * 32 <= 65536, "a cell's Morton code is stored in 16 bits");

// Host threads and their input ranges: range t is [t * n / T, (t + 1) * n / T),
// so that ranks and scatter positions follow input order.
struct Ranges {
    size_t n = 0;
    int count = 1;
    [[nodiscard]] size_t begin(int t) const { return size_t(uint64_t(n) * uint64_t(t) / uint64_t(count)); }
};

template <class Fn>
void forRanges(const Ranges& r, Fn&& fn) {
    core::parallelChunks(size_t(r.count), 1, r.count, [&](size_t t0, size_t t1, int) {
        for (size_t t = t0; t < t1; ++t) fn(int(t), r.begin(int(t)), r.begin(int(t) + 1));
    });
}

// blockOf's mark of a shared cell (its first block's number beside it):
// blocks are fewer than 2^31 (at most 2^12 groups and a block per piece).
constexpr uint32_t kSharedBlock = uint32_t(1) << 31;

// A shared cell's points by rank in input order over its `span` pieces:
// rank r (of `total`) goes to piece floor(r * span / total) of the cell's.
uint32_t pieceOfRank(uint64_t rank, uint64_t span, uint64_t total) { return uint32_t(rank * span / total); }

// The ranks [begin, end) that pieceOfRank sends to piece m of the cell's:
// floor(r * span / total) >= m exactly when r >= ceil(m * total / span).
struct PieceRanks {
    uint64_t begin = 0, end = 0;
};
PieceRanks pieceRanks(uint64_t m, uint64_t span, uint64_t total) {
    return {(m * total + span - 1) / span, ((m + 1) * total + span - 1) / span};
}

// A host range's scatter into its runs of a set's gathered arrays (points,
// input indices, cells where kept), one run per block. Each block's next 16
// points wait in a buffer placed as their destinations lie in cache lines;
// a buffer that ends on a line boundary of the destinations goes out at
// once, a whole group of 16 (three lines of points, one of indices, one of
// cells) with streaming stores, which write the lines without reading them
// first (an ordinary store reads each destination line from memory before
// writing it; on the H200 machine's host the torus quarter's scatter took
// 1.85-2.25 s with ordinary stores, 1.28-1.49 s so). A run's first and last
// partial groups, and every write where the arrays are not 64-byte aligned
// or under a sanitizer, are ordinary stores. Each range's runs are its own
// (the lines a streaming store writes lie inside one run), so ranges run
// at once; finish() makes the streaming stores visible before the range's
// thread ends.
// One counter a block (its next destination; the buffer's slot is its low
// bits); a run of points goes in through putRun, whose loop keeps the
// arrays' addresses in registers. On one H200's 16-core host the torus
// quarter's scatter 882-1022 -> 863-912 ms against slots prefetched ahead
// (the call's total level; on 2 cores 466-511 -> 408-424 ms for 30M points,
// one thread); the prefetch had measured level against the base + fill
// pair before it (docs/bench/scale, session 19). A buffered point and its
// input index share a 16-byte slot, so that a put touches one line of the
// buffers, not two (a flush copies the group apart into its two arrays):
// on 2 cores the scatter 372-378 -> 354-359 ms (70M points, 2 threads).
class BlockWriter {
public:
    static constexpr uint32_t kGroup = 16;  // points: 192 bytes = 3 lines; indices and cells: 1 line
    // Blocks past this are written directly (the buffers: 320 bytes a block,
    // and its first destination).
    static constexpr size_t kMaxBlocks = size_t(1) << 14;

    BlockWriter(SpatialPieces::Set& set, std::vector<uint64_t>& next)
        : m_points(set.points.data()),
          m_input(set.input.data()),
          m_cell(set.cell.empty() ? nullptr : set.cell.data()),
          m_next(next) {
        const auto aligned = [](const void* p) { return reinterpret_cast<uintptr_t>(p) % 64 == 0; };
        m_buffered = next.size() <= kMaxBlocks;
#if defined(RTHDIST_STREAMING_STORES)
        m_streaming =
            m_buffered && aligned(m_points) && aligned(m_input) && (m_cell == nullptr || aligned(m_cell));
#else
        (void)aligned;
#endif
        if (m_buffered) {
            m_first = next;
            m_slots.resize(next.size() * kGroup);
            if (m_cell != nullptr) m_bufCell.resize(next.size() * kGroup);
        }
    }

    void put(uint32_t block, const glm::vec3& p, uint32_t input, uint32_t cell) {
        const uint64_t at = m_next[block]++;  // this point's destination
        if (!m_buffered) {
            m_points[at] = p;
            m_input[at] = input;
            if (m_cell != nullptr) m_cell[at] = cell;
            return;
        }
        const size_t slot = size_t(block) * kGroup + at % kGroup;
        m_slots[slot] = Slot{p, input};
        if (m_cell != nullptr) m_bufCell[slot] = cell;
        if ((at + 1) % kGroup == 0) flush(block, at + 1);
    }

    // A run of points: points[i] into block blocks[i], input index first +
    // i, cell cells[i]. Without kept cells (the usual case) a loop of its
    // own, whose arrays' addresses stay in registers.
    void putRun(const uint32_t* blocks, const glm::vec3* points, uint32_t first, const uint16_t* cells,
                size_t n) {
        if (!m_buffered || m_cell != nullptr) {
            for (size_t i = 0; i < n; ++i) put(blocks[i], points[i], first + uint32_t(i), cells[i]);
            return;
        }
        uint64_t* const next = m_next.data();
        Slot* const slots = m_slots.data();
        for (size_t i = 0; i < n; ++i) {
            const uint32_t block = blocks[i];
            const uint64_t at = next[block]++;
            Slot& slot = slots[size_t(block) * kGroup + at % kGroup];
            slot.p = points[i];
            slot.input = first + uint32_t(i);
            if ((at + 1) % kGroup == 0) flush(block, at + 1);
        }
    }

    // The partial groups left, then a fence for the streaming stores.
    void finish() {
        if (m_buffered)
            for (uint32_t b = 0; b < m_next.size(); ++b)
                if (m_next[b] % kGroup != 0) flush(b, m_next[b]);
#if defined(RTHDIST_STREAMING_STORES)
        if (m_streaming) _mm_sfence();
#endif
    }

private:
    // The buffered points of `block` whose destinations lie in [first, end):
    // the group that `end` closes (or the last, partial one), from the
    // block's first destination in this range on.
    void flush(uint32_t block, uint64_t end) {
        const uint64_t first = std::max((end - 1) / kGroup * kGroup, m_first[block]);
        const size_t base = size_t(block) * kGroup;
#if defined(RTHDIST_STREAMING_STORES)
        if (m_streaming && end - first == kGroup) {  // a whole, aligned group
            alignas(64) glm::vec3 points[kGroup];
            alignas(64) uint32_t input[kGroup];
            for (uint32_t k = 0; k < kGroup; ++k) {
                points[k] = m_slots[base + k].p;
                input[k] = m_slots[base + k].input;
            }
            stream(m_points + first, points, kGroup * sizeof(glm::vec3));
            stream(m_input + first, input, kGroup * sizeof(uint32_t));
            if (m_cell != nullptr) stream(m_cell + first, &m_bufCell[base], kGroup * sizeof(uint32_t));
            return;
        }
#endif
        for (uint64_t at = first; at < end; ++at) {
            m_points[at] = m_slots[base + at % kGroup].p;
            m_input[at] = m_slots[base + at % kGroup].input;
            if (m_cell != nullptr) m_cell[at] = m_bufCell[base + at % kGroup];
        }
    }

#if defined(RTHDIST_STREAMING_STORES)
    static void stream(void* to, const void* from, size_t bytes) {
        auto* d = static_cast<__m128i*>(to);
        const auto* s = static_cast<const char*>(from);
        for (size_t k = 0; k < bytes / 16; ++k)
            _mm_stream_si128(d + k, _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + 16 * k)));
    }
#endif

    glm::vec3* m_points;
    uint32_t* m_input;
    uint32_t* m_cell;
    std::vector<uint64_t>& m_next;  // each block's next destination
    std::vector<uint64_t> m_first;  // each block's first destination in this range
    bool m_buffered = false;
    [[maybe_unused]] bool m_streaming = false;  // read only where streaming stores exist
    // A buffered point and its input index in one 16-byte slot: a put
    // touches one line of the buffers, not two.
    struct alignas(16) Slot {
        glm::vec3 p;
        uint32_t input;
    };
    std::vector<Slot> m_slots;
    std::vector<uint32_t> m_bufCell;
};

}  // namespace

template <class Fn>
bool SpatialPieces::forCellsInBox(const glm::vec3& q, double radius, Fn&& fn) const {
    uint32_t lo[3], hi[3];
    uint64_t cells = 1;
    for (int axis = 0; axis < 3; ++axis) {
        lo[axis] = axisCell(double(q[axis]) - radius, axis);
        hi[axis] = axisCell(double(q[axis]) + radius, axis);
        cells *= hi[axis] - lo[axis] + 1;
    }
    if (cells > kNearCells) return false;
    for (uint32_t z = lo[2]; z <= hi[2]; ++z)
        for (uint32_t y = lo[1]; y <= hi[1]; ++y)
            for (uint32_t x = lo[0]; x <= hi[0]; ++x)
                if (!fn(core::mortonEncode(x, y, z))) return false;
    return true;
}

bool SpatialPieces::boxInPiece(const glm::vec3& q, double radius, uint32_t k) const {
    return forCellsInBox(q, radius, [&](uint32_t cell) {
        const uint32_t owner = m_owner[cell];
        return owner == k || owner == kEmpty;
    });
}

std::vector<core::Bounds> SpatialPieces::pieceBoxes() const {
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<core::Bounds> boxes(m_pieces, core::Bounds{glm::dvec3(inf), glm::dvec3(-inf)});
    const auto add = [&boxes](uint32_t k, const glm::dvec3& lo, const glm::dvec3& hi) {
        boxes[k].lo = glm::min(boxes[k].lo, lo);
        boxes[k].hi = glm::max(boxes[k].hi, hi);
    };
    const glm::dvec3 side(1.0 / m_inverse[0], 1.0 / m_inverse[1], 1.0 / m_inverse[2]);
    const glm::dvec3 origin(m_lo[0], m_lo[1], m_lo[2]);
    for (uint32_t z = 0; z < m_cells; ++z)
        for (uint32_t y = 0; y < m_cells; ++y)
            for (uint32_t x = 0; x < m_cells; ++x) {
                const uint32_t cell = core::mortonEncode(x, y, z);
                const uint32_t owner = m_owner[cell];
                if (owner == kEmpty) continue;
                const glm::dvec3 at(x, y, z);
                const glm::dvec3 lo = origin + at * side, hi = origin + (at + 1.0) * side;
                if (owner != kShared) {
                    add(owner, lo, hi);
                    continue;
                }
                for (uint32_t b = m_blockFirst[cell]; b < m_blockFirst[cell] + m_blockCount[cell]; ++b)
                    add(m_blockPiece[b], lo, hi);
            }
    for (int axis = 0; axis < 3; ++axis) {
        const double top = m_lo[axis] + double(m_cells) / m_inverse[axis];
        const double widen = 0x1p-36 * (std::abs(m_lo[axis]) + std::abs(top)) + 0x1p-1000;
        for (core::Bounds& box : boxes) {
            box.lo[axis] -= widen;
            box.hi[axis] += widen;
        }
    }
    return boxes;
}

bool SpatialPieces::blocksNear(const glm::vec3& q, double radius, uint32_t k,
                               std::vector<uint32_t>& blocks) const {
    blocks.clear();
    const bool few = forCellsInBox(q, radius, [&](uint32_t cell) {
        const uint32_t owner = m_owner[cell];
        if (owner == kEmpty || (owner != kShared && owner != k)) return true;
        for (uint32_t b = m_blockFirst[cell]; b < m_blockFirst[cell] + m_blockCount[cell]; ++b)
            if (m_blockPiece[b] == k) blocks.push_back(b);
        return true;
    });
    if (!few) return false;
    std::sort(blocks.begin(), blocks.end());
    blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
    return true;
}

SpatialPieces SpatialPieces::partition(Span a, Span b, double scale, PieceLimits limits, int threads,
                                       PieceOrder order, const core::Bounds* box, bool keepCells) {
    SpatialPieces out;
    out.m_scale = scale;
    const Span sets[2] = {a, b};
    const uint64_t limit[2] = {std::max<uint64_t>(limits.a, 1), std::max<uint64_t>(limits.b, 1)};
    threads = core::resolveThreads(threads, (a.size() + b.size()) / 65536 + 1);

    core::Clock::time_point pass = core::Clock::now();
    auto lap = [&pass](double& into) {
        into = core::msSince(pass);
        pass = core::Clock::now();
    };

    // The pair's box, scaled as searched (scaling by a power of two is
    // monotone, so the scaled box of a given box is that of the points).
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    if (box != nullptr) {
        lo = glm::dvec3(core::scaled(glm::vec3(box->lo), scale));
        hi = glm::dvec3(core::scaled(glm::vec3(box->hi), scale));
        out.m_magnitude = core::largestMagnitude(*box);
    }
    for (const Span s : sets) {
        if (s.empty() || box != nullptr) continue;
        std::vector<glm::dvec3> partLo(size_t(threads), glm::dvec3(core::scaled(s[0], scale)));
        std::vector<glm::dvec3> partHi = partLo;
        std::vector<float> partMagnitude(size_t(threads), 0.0f);
        core::parallelChunks(s.size(), size_t(1) << 16, threads, [&](size_t begin, size_t end, int w) {
            glm::vec3 l = core::scaled(s[begin], scale), h = l;
            float m = partMagnitude[size_t(w)];  // as core::largestMagnitude, in the same pass
            for (size_t i = begin; i < end; ++i) {
                const glm::vec3 p = core::scaled(s[i], scale);
                l = glm::min(l, p);
                h = glm::max(h, p);
                m = std::max({m, std::abs(s[i].x), std::abs(s[i].y), std::abs(s[i].z)});
            }
            partLo[size_t(w)] = glm::min(partLo[size_t(w)], glm::dvec3(l));
            partHi[size_t(w)] = glm::max(partHi[size_t(w)], glm::dvec3(h));
            partMagnitude[size_t(w)] = m;
        });
        for (int w = 0; w < threads; ++w) {
            lo = glm::min(lo, partLo[size_t(w)]);
            hi = glm::max(hi, partHi[size_t(w)]);
            out.m_magnitude = std::max(out.m_magnitude, double(partMagnitude[size_t(w)]));
        }
    }
    lap(out.m_times.box);
    out.m_cells = cellsPerAxisFor(a.size() + b.size());
    const uint32_t cellCount = out.m_cells * out.m_cells * out.m_cells;
    for (int axis = 0; axis < 3; ++axis) {
        out.m_lo[axis] = lo[axis];
        const double side = (hi[axis] - lo[axis]) / double(out.m_cells);
        out.m_inverse[axis] = side > 0.0 && std::isfinite(1.0 / side) ? 1.0 / side : 1.0;
    }

    // Each range's count of every cell, and each point's cell (its Morton
    // code, below 2^15: 16 bits) for the scatter. Stored, 2 bytes a point,
    // rather than computed again there: on 2 cores the partition of 70M
    // points 413-420 -> 335-344 ms, on one H200's 16-core host the torus
    // quarter's 1044-1164 -> 965-1010 ms (scatter 832-933 -> 696-734, keys
    // 210-230 -> 263-272; docs/bench/scale, session 20); 4 bytes a
    // point of fresh memory had cost more than the second computation in
    // session 16 (a grid of up to 64 a side then).
    constexpr size_t kRun = 1024;
    Ranges ranges[2];
    std::vector<std::vector<uint32_t>> counts[2];
    core::UninitVector<uint16_t> cellOf16[2];  // each point's cell, in input order
    for (int s = 0; s < 2; ++s) {
        const Span points = sets[s];
        ranges[s] = Ranges{points.size(), core::resolveThreads(threads, points.size() / 65536 + 1)};
        counts[s].assign(size_t(ranges[s].count), std::vector<uint32_t>(cellCount, 0u));
        cellOf16[s].resize(points.size());
        forRanges(ranges[s], [&](int t, size_t begin, size_t end) {
            std::vector<uint32_t>& mine = counts[s][size_t(t)];
            uint32_t keys[kRun];
            uint16_t* const cellOf = cellOf16[s].data();
            for (size_t r0 = begin; r0 < end; r0 += kRun) {
                const size_t n = std::min(end, r0 + kRun) - r0;
                cellsOf(out, points.data() + r0, scale, n, keys);
                for (size_t i = 0; i < n; ++i) {
                    ++mine[keys[i]];
                    cellOf[r0 + i] = uint16_t(keys[i]);
                }
            }
        });
    }

    lap(out.m_times.keys);

    // Cells in Morton order into pieces. A cell past a limit alone is shared:
    // its points go to `span` pieces of their own by rank in input order.
    std::vector<uint64_t> total[2] = {std::vector<uint64_t>(cellCount, 0),
                                      std::vector<uint64_t>(cellCount, 0)};
    for (int s = 0; s < 2; ++s)
        for (const std::vector<uint32_t>& c : counts[s])
            for (uint32_t cell = 0; cell < cellCount; ++cell) total[s][cell] += c[cell];
    out.m_owner.assign(cellCount, kEmpty);
    std::vector<uint32_t> firstPiece(cellCount, 0), span(cellCount, 1);
    uint64_t held[2] = {0, 0};
    uint32_t pieces = 0;
    bool open = false;  // the current piece holds a point
    for (uint32_t cell = 0; cell < cellCount; ++cell) {
        const uint64_t n[2] = {total[0][cell], total[1][cell]};
        if (n[0] + n[1] == 0) continue;
        if (n[0] > limit[0] || n[1] > limit[1]) {
            if (open) ++pieces;
            open = false;
            held[0] = held[1] = 0;
            const uint64_t m = std::max((n[0] + limit[0] - 1) / limit[0], (n[1] + limit[1] - 1) / limit[1]);
            out.m_owner[cell] = kShared;
            firstPiece[cell] = pieces;
            span[cell] = uint32_t(m);
            pieces += uint32_t(m);
            continue;
        }
        if (open && (held[0] + n[0] > limit[0] || held[1] + n[1] > limit[1])) {
            ++pieces;
            held[0] = held[1] = 0;
        }
        open = true;
        held[0] += n[0];
        held[1] += n[1];
        out.m_owner[cell] = pieces;
        firstPiece[cell] = pieces;
    }
    if (open) ++pieces;
    out.m_pieces = pieces;

    // Solid cells: a cell of one piece whose neighbours hold that piece's
    // points only, or none (boxInPiece's first test).
    out.m_solid.assign((cellCount + 63) / 64, 0);
    const auto side = int(out.m_cells);
    core::parallelChunks(cellCount, 4096, threads, [&](size_t begin, size_t end, int) {  // 64 cells a word
        for (size_t cell = begin; cell < end; ++cell) {
            const uint32_t owner = out.m_owner[cell];
            if (owner == kEmpty || owner == kShared) continue;
            int c[3] = {0, 0, 0};
            for (int bit = 0; bit < 7; ++bit)
                for (int axis = 0; axis < 3; ++axis) c[axis] |= int((cell >> (3 * bit + axis)) & 1u) << bit;
            bool solid = true;
            for (int dz = -1; dz <= 1 && solid; ++dz)
                for (int dy = -1; dy <= 1 && solid; ++dy)
                    for (int dx = -1; dx <= 1 && solid; ++dx) {
                        const int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
                        if (x < 0 || y < 0 || z < 0 || x >= side || y >= side || z >= side) continue;
                        const uint32_t o =
                            out.m_owner[core::mortonEncode(uint32_t(x), uint32_t(y), uint32_t(z))];
                        solid = o == owner || o == kEmpty;
                    }
            if (solid) out.m_solid[cell >> 6] |= uint64_t(1) << (cell & 63u);
        }
    });

    lap(out.m_times.plan);

    // The blocks each set is scattered into, in order: a block is a piece's
    // points in one group of 2^blockShift cells of consecutive Morton codes
    // (order kBlocks), or the whole piece (kInput); a shared cell's pieces
    // are a block each. Pieces are runs of cells in Morton order, so blocks
    // ordered by (piece, group) follow the cells' order.
    const uint32_t cellBits = 3 * uint32_t(std::countr_zero(out.m_cells));
    const uint32_t blockShift = cellBits > kBlockGroupBits ? cellBits - kBlockGroupBits : 0u;
    const auto groupOf = [&](uint32_t cell) {
        return order == PieceOrder::kBlocks ? cell >> blockShift : 0u;
    };
    // blockOf: m_blockFirst with a shared cell marked in the same word, so
    // that the scatter looks up one word a point.
    std::vector<uint32_t> blockOf(cellCount, 0);  // a cell's block (a shared cell's first | kSharedBlock)
    std::vector<uint32_t>& blockPiece = out.m_blockPiece;  // each block's piece
    out.m_blockFirst.assign(cellCount, 0);
    out.m_blockCount.assign(cellCount, 0);
    {
        uint64_t last = UINT64_MAX;  // (piece, group) of the latest block
        for (uint32_t cell = 0; cell < cellCount; ++cell) {
            const uint32_t owner = out.m_owner[cell];
            if (owner == kEmpty) continue;
            if (owner == kShared) {
                blockOf[cell] = uint32_t(blockPiece.size()) | kSharedBlock;
                out.m_blockFirst[cell] = uint32_t(blockPiece.size());
                out.m_blockCount[cell] = span[cell];
                for (uint32_t m = 0; m < span[cell]; ++m) blockPiece.push_back(firstPiece[cell] + m);
                last = UINT64_MAX;
                continue;
            }
            const uint64_t key = (uint64_t(owner) << 32) | groupOf(cell);
            if (key != last) {
                blockPiece.push_back(owner);
                last = key;
            }
            blockOf[cell] = uint32_t(blockPiece.size() - 1);
            out.m_blockFirst[cell] = blockOf[cell];
            out.m_blockCount[cell] = 1;
        }
    }
    const size_t blocks = blockPiece.size();

    // Each point's block, then a stable scatter by block.
    for (int s = 0; s < 2; ++s) {
        const Span points = sets[s];
        const Ranges& r = ranges[s];
        // A shared cell's rank base per range: the cell's points in earlier ranges.
        std::vector<std::vector<uint64_t>> rankBase(size_t(r.count));
        std::vector<uint32_t> sharedCells;
        for (uint32_t cell = 0; cell < cellCount; ++cell)
            if (span[cell] > 1) sharedCells.push_back(cell);
        for (int t = 0; t < r.count; ++t) rankBase[size_t(t)].resize(sharedCells.size());
        for (size_t j = 0; j < sharedCells.size(); ++j) {
            uint64_t before = 0;
            for (int t = 0; t < r.count; ++t) {
                rankBase[size_t(t)][j] = before;
                before += counts[s][size_t(t)][sharedCells[j]];
            }
        }
        // A point's block from its cell (and, in a shared cell, its rank
        // there in input order: the ranges run in order, so the scatter
        // below finds the same blocks with a fresh copy of the bases).
        // One lookup a point: a shared cell's entry carries kSharedBlock.
        auto blockOfPoint = [&](uint32_t cell, std::vector<uint64_t>& rank) {
            const uint32_t block = blockOf[cell];
            if ((block & kSharedBlock) == 0) return block;
            const auto j =
                size_t(std::lower_bound(sharedCells.begin(), sharedCells.end(), cell) - sharedCells.begin());
            return (block & ~kSharedBlock) + pieceOfRank(rank[j]++, span[cell], total[s][cell]);
        };
        // Each range's count of every block, from its counts of the cells: a
        // cell's points go to its block, a shared cell's ranks [base, base +
        // count) to the blocks whose rank intervals (pieceRanks) they meet.
        std::vector<std::vector<uint64_t>> perBlock(size_t(r.count), std::vector<uint64_t>(blocks, 0));
        forRanges(r, [&](int t, size_t, size_t) {
            std::vector<uint64_t>& mine = perBlock[size_t(t)];
            const std::vector<uint32_t>& cells = counts[s][size_t(t)];
            for (uint32_t cell = 0; cell < cellCount; ++cell)
                if (span[cell] == 1 && cells[cell] != 0) mine[blockOf[cell]] += cells[cell];
            for (size_t j = 0; j < sharedCells.size(); ++j) {
                const uint32_t cell = sharedCells[j];
                const uint64_t lo = rankBase[size_t(t)][j], hi = lo + cells[cell];
                if (lo == hi) continue;
                const uint32_t last = pieceOfRank(hi - 1, span[cell], total[s][cell]);
                for (uint32_t m = pieceOfRank(lo, span[cell], total[s][cell]); m <= last; ++m) {
                    const PieceRanks ranks = pieceRanks(m, span[cell], total[s][cell]);
                    const uint64_t from = std::max(lo, ranks.begin), to = std::min(hi, ranks.end);
                    if (from < to) mine[(blockOf[cell] & ~kSharedBlock) + m] += to - from;
                }
            }
        });
        // perBlock becomes each range's next position in each block; blocks
        // come in piece order, so piece k starts after the pieces before it.
        Set& set = s == 0 ? out.m_a : out.m_b;
        std::vector<uint64_t> inPiece(pieces, 0);
        uint64_t at = 0;
        set.blockStart.assign(blocks + 1, 0);
        for (size_t blk = 0; blk < blocks; ++blk) {
            set.blockStart[blk] = at;
            for (int t = 0; t < r.count; ++t) {
                const uint64_t n = perBlock[size_t(t)][blk];
                perBlock[size_t(t)][blk] = at;
                at += n;
                inPiece[blockPiece[blk]] += n;
            }
        }
        set.blockStart[blocks] = at;
        set.start.assign(pieces + 1, 0);
        for (uint32_t k = 0; k < pieces; ++k) set.start[k + 1] = set.start[k] + inPiece[k];
        set.points.resize(points.size());
        set.input.resize(points.size());
        if (keepCells) set.cell.resize(points.size());
        forRanges(r, [&](int t, size_t begin, size_t end) {
            BlockWriter writer(set, perBlock[size_t(t)]);
            std::vector<uint64_t>& rank = rankBase[size_t(t)];
            uint32_t blockIds[kRun];
            for (size_t r0 = begin; r0 < end; r0 += kRun) {
                const size_t n = std::min(end, r0 + kRun) - r0;
                const uint16_t* const cellOf = cellOf16[s].data() + r0;
                for (size_t i = 0; i < n; ++i) blockIds[i] = blockOfPoint(cellOf[i], rank);
                writer.putRun(blockIds, points.data() + r0, uint32_t(r0), cellOf, n);
            }
            writer.finish();
        });
    }
    lap(out.m_times.scatter);
    return out;
}

}  // namespace rthdist::api
