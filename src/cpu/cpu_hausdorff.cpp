// Exact directed Hausdorff distance with early break over a grid + BVH.
//
// Papers: RT-HDIST (Kim, Lee, Kim 2025) for the index space and the lower
// bound first; Taha & Hanbury, "An efficient algorithm for calculating the
// exact Hausdorff distance" (TPAMI 2015) for the early break and the ordering
// of queries.
//
// Why it is exact. Let f(q) be q's nearest squared distance in float (the
// minimum over all targets of the float expression used everywhere below) and
// f* = max_q f(q). The kill threshold K only ever takes values <= f*: it is
// either a float NN value of some query (a witness exists, value <= f*) or the
// witness-less bound dist(q, BV(T))^2 lowered by a relative 1e-5, below f* by
// more than float rounding. A query dies only when it has a point with float
// squared distance strictly below K, which the query realizing f* never has;
// so it is searched to the end and wins. Every other finished query reports
// its own f(q) <= f*. The search is over the adaptive-order BVH of
// target_index.hpp (whose header shows that a box is never farther than a
// target below it and that the collapse of identical copies keeps every
// minimum and its smallest index); it prunes a box only when its float
// distance exceeds the best point by a relative 1e-5, so finished searches
// return f(q) exactly, with the smallest target index among ties at a
// nonzero distance. A best distance of 0 ends a search at once: no target is
// closer, and the target reported is one at float distance 0 (a copy of the
// query point), not necessarily the smallest index among several.
// The seeds before the search (the previous query's bucket, the query's own
// grid cell when it holds at most kMaxCellScan targets, a search of the
// subtree around the previous query's nearest bucket) only lower the best
// distance with real targets, and a query they kill has a real point strictly
// below K, exactly as the full search would require; skipping a seed (a
// denser cell) changes the cost, never the result, so no query scans more
// than a bounded number of points before the BVH takes over. Queries come in
// their own adaptive order (cpu/adaptive_order.hpp: ties, such as copies of
// one point, in ascending input index): a query equal to the previous one has
// the same f(q) and a larger index, so it can neither die later nor win, and
// is skipped (per-point: it takes the previous query's target).
#include "cpu/cpu_hausdorff.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <vector>

#include "core/certificate.hpp"
#include "core/parallel.hpp"
#include "core/search_mutant.hpp"
#include "core/stopwatch.hpp"
#include "cpu/target_index.hpp"

namespace rthdist::cpu {

using core::parallelChunks;
using core::resolveThreads;
namespace {

// Internal 8-wide float vectors (GCC/Clang extension; SSE pairs, AVX when enabled).
#pragma GCC diagnostic ignored "-Wpsabi"
using v8f = float __attribute__((vector_size(32)));

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
// Boxes within (1 + kPruneSlack) of the best squared distance are still visited.
constexpr float kPruneSlack = 1e-5f;
// The witness-less box bound is lowered by this relative amount before use.
constexpr double kBoundShrink = 1e-5;
constexpr size_t kQueryChunk = 256;
constexpr size_t kSampleSize = 256;
// A query scans its own grid cell only when it holds at most this many
// targets (one refinement run); a denser cell is left to the BVH search.
constexpr uint32_t kMaxCellScan = kRefineRun;
// Level of the local subtree searched before the whole tree (8^2 buckets).
constexpr uint32_t kLocalLevel = 2;
// The per-point grid search (nearestInCells) takes cubes spanning at most
// this many cells per axis (3: 15% fewer instructions than 2 on the masks'
// organ boundaries, whose distances often exceed a cell; the BVH beyond).
constexpr uint32_t kGridSpan = 3;

using core::Clock;
using core::msSince;

inline v8f load8(const float* p) {
    v8f v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
inline v8f splat(float s) { return v8f{s, s, s, s, s, s, s, s}; }
// By reference: a 32-byte vector passed by value without AVX makes GCC note
// an ABI change (-Wpsabi) in every build.
inline float hmin(const v8f& v) {
    float m = v[0];
    for (int l = 1; l < 8; ++l) m = v[l] < m ? v[l] : m;
    return m;
}

struct Query {
    v8f x, y, z;
};

// Nearest candidate so far: float squared distance, input index, sorted position.
struct Best {
    float d2 = kInf;
    uint32_t target = kNone;
    uint32_t pos = kNone;
};

// The 8 sorted targets from `pos` (past a bucket's end: other real targets or
// the +inf padding; both harmless for a minimum over all targets).
inline void scan8(const TargetIndex& t, uint32_t pos, const Query& q, Best& best) {
    const v8f dx = q.x - load8(&t.x[pos]);
    const v8f dy = q.y - load8(&t.y[pos]);
    const v8f dz = q.z - load8(&t.z[pos]);
    const v8f d2 = dx * dx + dy * dy + dz * dz;
    if (!(hmin(d2) <= best.d2)) return;
    for (uint32_t l = 0; l < 8; ++l) {
        const uint32_t original = t.original[pos + l];
        if (d2[l] < best.d2 || (d2[l] == best.d2 && original < best.target)) {
            best = {d2[l], original, pos + l};
        }
    }
}

inline void scanRange(const TargetIndex& t, uint32_t first, uint32_t end, const Query& q, Best& best) {
    for (uint32_t pos = first; pos < end; pos += 8) scan8(t, pos, q, best);
}

// Squared float distance from q to the 8 child boxes of `node` (boxes
// 8 node .. 8 node + 7 of `level`), with the same operation order as scan8
// (so a box is never farther than its points).
inline v8f boxDistance8(const BoxLevel& level, uint32_t node, const Query& q) {
    const float* b = level.block(node);
    const v8f zero = splat(0.0f);
    v8f lo = load8(b) - q.x, hi = q.x - load8(b + 24);
    v8f dx = lo > hi ? lo : hi;
    dx = dx > zero ? dx : zero;
    lo = load8(b + 8) - q.y;
    hi = q.y - load8(b + 32);
    v8f dy = lo > hi ? lo : hi;
    dy = dy > zero ? dy : zero;
    lo = load8(b + 16) - q.z;
    hi = q.z - load8(b + 40);
    v8f dz = lo > hi ? lo : hi;
    dz = dz > zero ? dz : zero;
    return dx * dx + dy * dy + dz * dz;
}

// Squared float distance from (qx, qy, qz) to the box [lo, hi], with
// boxDistance8's operations (so a box is never farther than its points).
inline float boxDistance(const glm::vec3& lo, const glm::vec3& hi, float qx, float qy, float qz) {
    const float dx = std::max(std::max(lo.x - qx, qx - hi.x), 0.0f);
    const float dy = std::max(std::max(lo.y - qy, qy - hi.y), 0.0f);
    const float dz = std::max(std::max(lo.z - qz, qz - hi.z), 0.0f);
    return dx * dx + dy * dy + dz * dz;
}

struct SearchStats {
    uint64_t bucketsScanned = 0;  // (query, 8 targets) scans: hint, own cell and BVH buckets
};

// Moves cursor (a position in [0, cells]) to the first cell key >= key by
// galloping from where it is, either way (consecutive queries are neighbours,
// so their cells are near in key order); true when that cell is key's.
inline bool findCell(const TargetIndex& t, uint32_t key, uint32_t& cursor) {
    const uint32_t cells = t.cellCount();
    const uint32_t* keys = t.cellKey.data();
    if (cursor < cells && keys[cursor] < key) {
        uint32_t step = 1;
        while (cursor + step < cells && keys[cursor + step] < key) step *= 2;
        const uint32_t hi = std::min(cells, cursor + step + 1);
        cursor = uint32_t(std::lower_bound(keys + cursor, keys + hi, key) - keys);
    } else if (cursor > 0 && keys[cursor - 1] >= key) {
        uint32_t step = 1;
        while (step < cursor && keys[cursor - step - 1] >= key) step *= 2;
        const uint32_t lo = step < cursor ? cursor - step - 1 : 0;
        cursor = uint32_t(std::lower_bound(keys + lo, keys + cursor, key) - keys);
    }
    return cursor < cells && keys[cursor] == key;
}

// The query's own grid cell when it is small enough to scan (kMaxCellScan).
inline void scanOwnCell(const TargetIndex& t, uint32_t key, uint32_t& cursor, const Query& q, Best& best,
                        SearchStats& stats) {
    if (!findCell(t, key, cursor)) return;
    const uint32_t first = t.cellFirst[cursor], end = t.cellFirst[cursor + 1];
    if (end - first > kMaxCellScan) return;
    stats.bucketsScanned += (end - first + 7) / 8;
    scanRange(t, first, end, q, best);
}

inline bool sameQuery(const UninitVector<float>& x, const UninitVector<float>& y,
                      const UninitVector<float>& z, size_t i) {
    return x[i] == x[i - 1] && y[i] == y[i - 1] && z[i] == z[i - 1];
}

// Depth-first BVH search, nearest child first. Returns true as soon as a point
// strictly closer than `kill` is found (the query cannot raise the maximum);
// otherwise best holds the exact float nearest neighbour on return. A best
// distance of 0 ends the search at once (nothing is closer; among several
// targets at distance 0 the first found is kept).
// The search covers the subtree of node `node` of level `level` >= 1 (its
// children are on level - 1); level 0 (the default) means the root, i.e.
// every target.
bool searchTree(const TargetIndex& t, const Query& q, float kill, Best& best, SearchStats& stats,
                uint32_t level = 0, uint32_t node = 0) {
    if (best.d2 < kill) return true;
    if (best.d2 == 0.0f) return false;
    if (level == 0) level = uint32_t(t.levels.size() - 1);
    const bool mutant = core::searchMutant().load(std::memory_order_relaxed);  // tests only
    struct Entry {
        float d2;
        uint32_t level;
        uint32_t node;
    };
    std::array<Entry, 8 * 40> stack;
    int top = 0;
    stack[top++] = {0.0f, level, node};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.d2 > best.d2 * (1.0f + kPruneSlack)) continue;
        const uint32_t childLevel = e.level - 1;
        const BoxLevel& children8 = t.levels[childLevel];
        const uint32_t base = e.node * kFanout;
        const uint32_t real = std::min<uint32_t>(kFanout, children8.count - base);
        const v8f d2 = boxDistance8(children8, e.node, q);
        const float limit = best.d2 * (1.0f + kPruneSlack);
        Entry children[kFanout];
        int count = 0;
        for (uint32_t l = 0; l < real; ++l) {
            if (!(d2[l] <= limit)) continue;
            Entry c{d2[l], childLevel, base + l};
            int k = count++;
            while (k > 0 && children[k - 1].d2 > c.d2) {  // ascending
                children[k] = children[k - 1];
                --k;
            }
            children[k] = c;
        }
        if (childLevel == 0) {
            for (int k = 0; k < count; ++k) {
                if (children[k].d2 > best.d2 * (1.0f + kPruneSlack)) break;
                ++stats.bucketsScanned;
                const uint32_t bucket = children[k].node;
                // Tests only (core/search_mutant.hpp): a search that misses candidates.
                if (mutant && bucket % 3 == 1) continue;
                scanRange(t, t.bucketFirst[bucket], t.bucketFirst[bucket + 1], q, best);
                if (best.d2 < kill) return true;
                if (best.d2 == 0.0f) return false;
            }
        } else {
            for (int k = count - 1; k >= 0; --k) stack[top++] = children[k];
        }
    }
    return false;
}

// Running maximum of non-negative float squared distances (bit order = value order).
void atomicMax(std::atomic<uint32_t>& target, float value) {
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    uint32_t seen = target.load(std::memory_order_relaxed);
    while (seen < bits && !target.compare_exchange_weak(seen, bits, std::memory_order_relaxed)) {
    }
}

struct Winner {
    float d2 = -1.0f;
    uint32_t query = kNone;
    uint32_t target = kNone;
    void offer(float d, uint32_t q, uint32_t t) {
        if (d > d2 || (d == d2 && q < query)) *this = {d, q, t};
    }
};

struct DirectedOutput {
    Directed directed;
    core::DirectionBand
        band;  // the certificate's band (core/certificate.hpp), for a proof from the originals
    // A query whose search found no target (impossible for finite, scaled
    // input; kept as an internal error rather than a read past the arrays).
    bool lostQuery = false;
    bool cancelled = false;  // CallOptions::cancel was set: the output is incomplete
    double indexMs = 0.0, cullMs = 0.0, searchMs = 0.0, refineMs = 0.0;
    double certificateMs = 0.0;  // proveDirection: the band settled in double (after refine)
    // With a floor: the queries above it, by input index (core/per_point_floor.hpp).
    std::optional<std::vector<detail::QueryNearest>> above;
};

// Stage boundaries of one direction as fractions of it (search dominates).
constexpr double kIndexDone = 0.1, kCullDone = 0.15, kSearchDone = 0.95;

// CallOptions::progress for one direction, which covers [base, base + span)
// of the call. Only the calling thread (worker 0 of parallelChunks) reports,
// and at most once per percent of the direction, so a callback that prints
// stays cheap. Every worker polls the cancel flag once per chunk of queries.
class Progress {
public:
    Progress(const CallOptions& options, double base, double span)
        : m_fn(options.progress ? &options.progress : nullptr),
          m_cancel(options.cancel),
          m_base(base),
          m_span(span) {}
    [[nodiscard]] bool cancelled() const {
        return m_cancel != nullptr && m_cancel->load(std::memory_order_relaxed);
    }
    // fraction: of this direction, 0..1.
    void report(const char* stage, double fraction) {
        if (m_fn == nullptr) return;
        fraction = std::max(fraction, m_last);  // rounding must not step back
        if (stage == m_stage && fraction < m_last + 0.01 && fraction < 1.0) return;
        m_last = fraction;
        m_stage = stage;
        (*m_fn)(stage, m_base + m_span * std::clamp(fraction, 0.0, 1.0));
    }
    // A worker finished `count` more of the direction's `total` queries.
    void queriesDone(size_t count, size_t total, int worker) {
        const size_t finished = m_queriesDone.fetch_add(count, std::memory_order_relaxed) + count;
        if (worker == 0) {
            report("search", kCullDone + (kSearchDone - kCullDone) * double(finished) / double(total));
        }
    }

private:
    const std::function<void(const char*, double)>* m_fn;
    const std::atomic<bool>* m_cancel;
    double m_base, m_span;
    double m_last = -1.0;
    const char* m_stage = nullptr;
    std::atomic<size_t> m_queriesDone{0};
};

// Cell keys of the queries in T's grid, and how far they reach outside BV(T).
struct QueryKeys {
    UninitVector<uint32_t> key;  // per query of the query order: its cell key (clamped outside the grid)
    double farthest2 = 0.0;      // largest squared distance from a query to BV(T)
};

// Queries in their own adaptive order, each with its cell key in the target
// grid; the same pass finds the largest distance from a query to BV(T).
QueryKeys keyQueries(const SetOrder& qOrder, const core::GridSpec& g, const core::Bounds& box, int threads) {
    const size_t nq = qOrder.keyed.size();
    QueryKeys out{UninitVector<uint32_t>(nq), 0.0};
    std::vector<double> farthest(size_t(threads), 0.0);
    parallelChunks(nq, 1 << 16, threads, [&](size_t begin, size_t end, int w) {
        double far = 0.0;
        for (size_t i = begin; i < end; ++i) {
            const glm::dvec3 dp(qOrder.x[i], qOrder.y[i], qOrder.z[i]);
            out.key[i] = core::cellKey(dp, g);
            const glm::dvec3 d = glm::max(glm::max(box.lo - dp, dp - box.hi), glm::dvec3(0.0));
            far = std::max(far, d.x * d.x + d.y * d.y + d.z * d.z);
        }
        farthest[size_t(w)] = std::max(farthest[size_t(w)], far);
    });
    out.farthest2 = *std::max_element(farthest.begin(), farthest.end());
    return out;
}

// One direction h(Q, T): the queries (input order and their adaptive order,
// scaled, with cell keys) and the target index.
struct Direction {
    std::span<const glm::vec3> queries, targets;  // input order, before `scale`
    const UninitVector<float>& qx;                // the scaled queries in their order
    const UninitVector<float>& qy;
    const UninitVector<float>& qz;
    const UninitVector<uint64_t>& qKeyed;  // (fine key << 32 | input index) in that order
    const UninitVector<uint32_t>& qKey;    // their cell keys in t's grid
    const TargetIndex& t;
    double scale;
    int threads;
    core::Bounds qBounds, tBounds;  // both sets' boxes, scaled

    [[nodiscard]] size_t queryCount() const { return queries.size(); }
    [[nodiscard]] Query query(size_t i) const { return {splat(qx[i]), splat(qy[i]), splat(qz[i])}; }
    // Query i is a copy of query i - 1 (i > 0).
    [[nodiscard]] bool sameAsPrevious(size_t i) const { return sameQuery(qx, qy, qz, i); }
    // The cell cursor (findCell) of a chunk starting at query `begin`.
    [[nodiscard]] uint32_t firstCell(size_t begin) const {
        const uint32_t* keys = t.cellKey.data();
        return uint32_t(std::lower_bound(keys, keys + t.cellCount(), qKey[begin]) - keys);
    }
};

// Where the previous query's search ended, the seeds of the next one: its
// nearest (or killing) point and that point's bucket; and the cell cursor.
struct Seeds {
    uint32_t bucket = kNone;  // kNone: no previous query in this chunk (or it was lost)
    uint32_t pos = kNone;     // sorted position of the point
    uint32_t cursor = 0;

    void follow(const TargetIndex& t, const Best& best) {
        pos = best.pos;
        bucket = t.bucketOf[best.pos];
    }
};

// The counters both kinds of pass fill alike.
Counters passCounters(const Direction& d, const std::vector<SearchStats>& stats) {
    Counters c;
    c.bits = uint32_t(d.t.grid.bits);
    c.occupiedCells = d.t.cellCount();
    c.queries = d.queryCount();
    c.iterations = 1;
    for (const SearchStats& s : stats) c.candidatePairs += s.bucketsScanned;
    return c;
}

// The cells of recent lookups (key -> position in cellKey, or kNone when not
// occupied), direct-mapped: consecutive queries of a chunk are Morton
// neighbours and look up the same few cells, so most lookups skip findCell.
struct CellCache {
    static constexpr uint32_t kSlots = 64;
    std::array<uint32_t, kSlots> key;
    std::array<uint32_t, kSlots> cell;
    CellCache() { key.fill(kNone); }

    // Position of `k` in t.cellKey, or kNone.
    uint32_t find(const TargetIndex& t, uint32_t k, uint32_t& cursor) {
        const uint32_t slot = (k ^ (k >> 6) ^ (k >> 12)) % kSlots;
        if (key[slot] == k) return cell[slot];
        key[slot] = k;
        cell[slot] = findCell(t, k, cursor) ? cursor : kNone;
        return cell[slot];
    }
};

// Grid cells of [lo, hi] on one axis (cellCoord is monotone, so every
// target with a coordinate in the interval lies in one of them).
struct CellSpan {
    uint32_t first, last;
};
inline CellSpan cellSpan(double lo, double hi, double origin, const core::GridSpec& g) {
    return {core::cellCoord(lo, origin, g.cellSize, g.cellsPerAxis),
            core::cellCoord(hi, origin, g.cellSize, g.cellsPerAxis)};
}

// The exact float nearest neighbour by the grid instead of the BVH, when the
// cube of half-width r around the query (r: the seeds' best distance, raised
// past the float rounding of any squared distance that could tie or beat it)
// meets at most kGridSpan cells per axis, each of at most kMaxCellScan targets:
// every target that could beat or tie the best lies in those cells
// (cellCoord is the target keys' own, monotone function), and scanning them
// all applies the search's (distance, input index) order. False (best
// untouched beyond what it scanned) when the cube is larger or a cell
// denser: the BVH search then runs.
inline bool nearestInCells(const TargetIndex& t, const Query& q, float qx, float qy, float qz,
                           uint32_t ownKey, uint32_t& cursor, CellCache& cache, Best& best,
                           SearchStats& stats) {
    if (!(best.d2 < kInf)) return false;
    const core::GridSpec& g = t.grid;
    const double r = std::sqrt(double(best.d2) * (1.0 + 1e-5)) * (1.0 + 1e-12);
    const CellSpan sx = cellSpan(double(qx) - r, double(qx) + r, g.origin.x, g);
    const CellSpan sy = cellSpan(double(qy) - r, double(qy) + r, g.origin.y, g);
    const CellSpan sz = cellSpan(double(qz) - r, double(qz) + r, g.origin.z, g);
    if (sx.last - sx.first >= kGridSpan || sy.last - sy.first >= kGridSpan || sz.last - sz.first >= kGridSpan)
        return false;
    // The cells with their box distances, nearest first (the query's own
    // cell, when small, was scanned already by scanOwnCell).
    struct Near {
        float d2;
        uint32_t cell;
    };
    std::array<Near, kGridSpan * kGridSpan * kGridSpan> near{};
    int count = 0;
    for (uint32_t z = sz.first; z <= sz.last; ++z)
        for (uint32_t y = sy.first; y <= sy.last; ++y)
            for (uint32_t x = sx.first; x <= sx.last; ++x) {
                const uint32_t key = core::mortonEncode(x, y, z);
                const uint32_t cell = cache.find(t, key, cursor);
                if (cell == kNone) continue;
                const uint32_t size = t.cellFirst[cell + 1] - t.cellFirst[cell];
                if (size > kMaxCellScan) return false;
                if (key == ownKey) continue;
                Near c{boxDistance(t.cellLo[cell], t.cellHi[cell], qx, qy, qz), cell};
                int k = count++;
                while (k > 0 && near[size_t(k - 1)].d2 > c.d2) {
                    near[size_t(k)] = near[size_t(k - 1)];
                    --k;
                }
                near[size_t(k)] = c;
            }
    for (int c = 0; c < count; ++c) {
        if (near[size_t(c)].d2 > best.d2 * (1.0f + kPruneSlack)) break;
        const uint32_t first = t.cellFirst[near[size_t(c)].cell], end = t.cellFirst[near[size_t(c)].cell + 1];
        stats.bucketsScanned += (end - first + 7) / 8;
        scanRange(t, first, end, q, best);
    }
    return true;
}

// Query i's exact float nearest neighbour (no early break): the previous
// query's nearest bucket and the query's own cell (when small) seed the best
// distance; then the grid cells around the query when few (nearestInCells),
// else the BVH search to the end with kill = 0.
inline Best nearestOf(const Direction& d, size_t i, Seeds& seeds, CellCache& cells, SearchStats& stat) {
    const TargetIndex& t = d.t;
    const Query q = d.query(i);
    Best best;
    if (seeds.bucket != kNone) {
        ++stat.bucketsScanned;
        scanRange(t, t.bucketFirst[seeds.bucket], t.bucketFirst[seeds.bucket + 1], q, best);
    }
    scanOwnCell(t, d.qKey[i], seeds.cursor, q, best, stat);
    if (best.d2 == 0.0f) return best;  // nothing is closer; among zeros the first found is kept
    if (!nearestInCells(t, q, d.qx[i], d.qy[i], d.qz[i], d.qKey[i], seeds.cursor, cells, best, stat))
        searchTree(t, q, 0.0f, best, stat);  // kill 0: never breaks early
    return best;
}

inline bool killedBySeeds(const Direction& d, size_t i, const Query& q, float k, Seeds& seeds, Best& best,
                          SearchStats& stat);

// Query i's exact nearest target, or a target nearer than `kill` (> 0)
// found on the way (the early break of a per-point floor): the seeds of the
// early-break pass first (the previous query's point, its bucket, the own
// cell, the subtree around them), then the search with the kill.
inline Best nearestAbove(const Direction& d, size_t i, float kill, Seeds& seeds, CellCache& cells,
                         SearchStats& stat) {
    const TargetIndex& t = d.t;
    const Query q = d.query(i);
    Best best;
    if (killedBySeeds(d, i, q, kill, seeds, best, stat)) return best;
    if (!nearestInCells(t, q, d.qx[i], d.qy[i], d.qz[i], d.qKey[i], seeds.cursor, cells, best, stat))
        searchTree(t, q, kill, best, stat);
    return best;
}

// The certificate's slack e for a direction (core/certificate.hpp): 2^-20 of
// the largest |coordinate| of both sets (scaled, as searched).
double slackOf(const Direction& d) {
    return core::searchSlack(std::max(core::largestMagnitude(d.qBounds), core::largestMagnitude(d.tBounds)));
}

core::DirectionBand bandOf(const Direction& d, std::vector<core::BandQuery> queries, double hf) {
    core::DirectionBand band;
    band.present = true;
    band.queries = std::move(queries);
    band.hf = hf;
    band.slack = slackOf(d);
    band.scale = d.scale;
    return band;
}

// The certificate from the float sets the backend searched (their own
// coordinates; HausdorffResult::proofMaterial keeps the band for a proof
// from the caller's): out.directed takes the proof's witness when it holds.
void proveDirection(const Direction& d, DirectedOutput& out, PerPoint* perPoint = nullptr) {
    const auto start = Clock::now();
    const core::PointAt query = [&d](uint64_t i) { return glm::dvec3(d.queries[i]); };
    const core::PointAt target = [&d](uint64_t i) { return glm::dvec3(d.targets[i]); };
    const core::DirectedProof proof = core::proveOnHost(out.band, query, PointView(d.targets), d.threads);
    core::applyProof(out.directed, proof, query, target, perPoint);
    if (!proof.proven) out.band.failure = proof.failure;
    out.certificateMs = msSince(start);
}

// Every query's exact float nearest neighbour. A query equal to the previous
// one takes its nearest target. Fills `nearest` (input order) with the target
// index and the double distance recomputed from the pair.
// With a kill threshold (core::PerPointFloor::kill2, > 0) a query with a
// target nearer than it stops there, and only the others are listed, in
// `above` (by input index), the arrays left empty: a piece's call of the
// out-of-core route needs a handful of its queries, and the arrays' fresh
// pages cost more than the search (their zeroing 28 % of a torus pair's
// pieces on this repository's 2-core VM).
void perPointPass(const Direction& d, PerPoint& nearest, std::vector<SearchStats>& stats, Progress& progress,
                  std::atomic<bool>& lost, float kill2, std::vector<detail::QueryNearest>* above) {
    const size_t nq = d.queryCount();
    if (above == nullptr) {
        nearest.distance.assign(nq, 0.0);
        nearest.nearest.assign(nq, 0);
    }
    std::vector<std::vector<detail::QueryNearest>> parts(
        above != nullptr ? (nq + kQueryChunk - 1) / kQueryChunk : 0);
    parallelChunks(nq, kQueryChunk, d.threads, [&](size_t begin, size_t end, int w) {
        if (progress.cancelled()) return;
        SearchStats stat;
        Seeds seeds{kNone, kNone, d.firstCell(begin)};
        CellCache cells;
        uint32_t target = kNone;  // the previous query's nearest target (input index)
        for (size_t i = begin; i < end; ++i) {
            const uint32_t src = uint32_t(d.qKeyed[i]);  // input index
            if (!(i > begin && seeds.bucket != kNone && d.sameAsPrevious(i))) {
                const Best best = kill2 > 0.0f ? nearestAbove(d, i, kill2, seeds, cells, stat)
                                               : nearestOf(d, i, seeds, cells, stat);
                if (best.pos == kNone) {
                    lost.store(true, std::memory_order_relaxed);
                    seeds.bucket = kNone;
                    continue;
                }
                seeds.follow(d.t, best);
                target = best.d2 < kill2 ? core::kBelowFloor : best.target;
            }
            if (above != nullptr) {
                if (target != core::kBelowFloor) parts[begin / kQueryChunk].push_back({src, target});
                continue;
            }
            const glm::dvec3 diff = glm::dvec3(d.queries[src]) - glm::dvec3(d.targets[target]);
            nearest.distance[src] = std::sqrt(diff.x * diff.x + diff.y * diff.y + diff.z * diff.z);
            nearest.nearest[src] = target;
        }
        stats[size_t(w)].bucketsScanned += stat.bucketsScanned;
        progress.queriesDone(end - begin, nq, w);
    });
    if (above == nullptr) return;
    *above = core::concatenateParts<std::vector<detail::QueryNearest>>(parts);
    std::sort(above->begin(), above->end(), [](const auto& x, const auto& y) { return x.query < y.query; });
}

// Every query's NN: no lower bound, no kill. The witness is the largest
// double distance (smallest query index among ties), so it is consistent
// with the per-point array by construction.
// With a floor (kill2 > 0) only the queries above it (out.above) and the
// counters: no witness, band or proof (core/per_point_floor.hpp).
void perPointDirection(const Direction& d, PerPoint& perPoint, Progress& progress, DirectedOutput& out,
                       float kill2) {
    auto start = Clock::now();
    std::vector<SearchStats> stats(static_cast<size_t>(d.threads));
    std::atomic<bool> lost{false};
    if (kill2 > 0.0f) out.above.emplace();
    perPointPass(d, perPoint, stats, progress, lost, kill2, out.above ? &*out.above : nullptr);
    out.lostQuery = lost.load();
    out.cancelled = progress.cancelled();
    if (out.cancelled) return;
    out.searchMs = msSince(start);
    progress.report("refine", kSearchDone);
    if (kill2 > 0.0f) {
        out.directed.counters = passCounters(d, stats);
        out.directed.counters.survivingQueries = d.queryCount();
        progress.report("refine", 1.0);
        return;
    }
    start = Clock::now();
    size_t win = 0;
    for (size_t i = 1; i < d.queryCount(); ++i) {
        if (perPoint.distance[i] > perPoint.distance[win]) win = i;
    }
    Directed& r = out.directed;
    r.queryIndex = uint32_t(win);
    r.targetIndex = perPoint.nearest[win];
    r.queryPoint = d.queries[r.queryIndex];
    r.targetPoint = d.targets[r.targetIndex];
    r.distance = perPoint.distance[win];
    r.counters = passCounters(d, stats);
    r.counters.survivingQueries = d.queryCount();
    // The band from the double distances of the float nearest pairs (each
    // within e / s of the query's exact nearest distance): those within 2e of
    // the largest, whose search-unit value stands for the float maximum.
    const double slack = slackOf(d), top = perPoint.distance[win] * d.scale;
    std::vector<core::BandQuery> band;
    for (size_t i = 0; i < d.queryCount(); ++i)
        if (perPoint.distance[i] * d.scale >= top - 2.0 * slack) band.push_back({i, perPoint.nearest[i]});
    out.band = bandOf(d, std::move(band), top);
    out.refineMs = msSince(start);
    proveDirection(d, out, &perPoint);  // the settled queries' entries as proven
    progress.report("refine", 1.0);
}

// Per-worker results of the early-break pass (the sample's winners seed it).
struct PassTally {
    std::vector<Winner> winners;
    std::vector<SearchStats> stats;
    std::vector<uint64_t> culled, surviving;

    explicit PassTally(int threads)
        : winners(size_t(threads)),
          stats(size_t(threads)),
          culled(size_t(threads)),
          surviving(size_t(threads)) {}
};

// The first kill threshold: the exact NN of a strided sample of the queries
// (witnessed, offered to the tally's winners) or the box bound lowered by
// kBoundShrink, whichever is larger.
float lowerBound(const Direction& d, double boxBound2, PassTally& tally) {
    const size_t nq = d.queryCount();
    const size_t samples = std::min(nq, kSampleSize);
    parallelChunks(samples, 32, d.threads, [&](size_t begin, size_t end, int w) {
        Winner winner;
        SearchStats stat;
        for (size_t s = begin; s < end; ++s) {
            const uint32_t i = uint32_t(s * nq / samples);
            const glm::vec3 p = scaled(d.queries[i], d.scale);
            const Query q{splat(p.x), splat(p.y), splat(p.z)};
            Best best;
            searchTree(d.t, q, 0.0f, best, stat);
            winner.offer(best.d2, i, best.target);
        }
        tally.winners[size_t(w)].offer(winner.d2, winner.query, winner.target);
        tally.stats[size_t(w)].bucketsScanned += stat.bucketsScanned;
    });
    float sampleMax = 0.0f;
    for (const Winner& w : tally.winners) sampleMax = std::max(sampleMax, w.d2);
    const double bound2 = boxBound2 * (1.0 - kBoundShrink);
    return std::max(sampleMax, float(bound2));
}

// One chunk's tallies of the early-break pass, published once: per-worker
// slots share cache lines.
struct ChunkTally {
    Winner winner;
    uint64_t culled = 0, surviving = 0;
    bool lost = false;
};

// The seeds of query i before the full search: the previous query's killing
// point alone (it kills most Morton neighbours), its bucket, the query's own
// cell, then the subtree around the previous query's nearest bucket (its
// ancestor kLocalLevel levels up, in cache). True when one of them holds a
// point strictly closer than k; the seeds then follow that point, except
// when the previous point itself killed.
inline bool killedBySeeds(const Direction& d, size_t i, const Query& q, float k, Seeds& seeds, Best& best,
                          SearchStats& stat) {
    const TargetIndex& t = d.t;
    if (seeds.bucket != kNone) {
        const float dx = d.qx[i] - t.x[seeds.pos], dy = d.qy[i] - t.y[seeds.pos],
                    dz = d.qz[i] - t.z[seeds.pos];
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < k) {
            best = {d2, t.original[seeds.pos], seeds.pos};  // the killing point (the certificate's band)
            return true;
        }
        ++stat.bucketsScanned;
        scanRange(t, t.bucketFirst[seeds.bucket], t.bucketFirst[seeds.bucket + 1], q, best);
        if (best.d2 < k) {
            seeds.follow(t, best);
            return true;
        }
    }
    scanOwnCell(t, d.qKey[i], seeds.cursor, q, best, stat);
    if (best.d2 < k || (seeds.bucket != kNone && kLocalLevel + 1 < t.levels.size() &&
                        searchTree(t, q, k, best, stat, kLocalLevel, seeds.bucket >> (3 * kLocalLevel)))) {
        seeds.follow(t, best);
        return true;
    }
    return false;
}

// Every query's best pair when the pass ends (a real target: its nearest,
// or the point that killed it), by position in the queries' order: the
// certificate's band is read from it.
struct QueryBests {
    float* d2;
    uint32_t* target;  // input index
};

// Query i of the early-break pass: culled (a copy of the previous query, or
// killed by a seed), killed in the BVH search, or searched to the end, when
// it is offered as the witness and raises the kill threshold.
inline void searchQuery(const Direction& d, size_t i, bool first, std::atomic<uint32_t>& kill, Seeds& seeds,
                        ChunkTally& tally, SearchStats& stat, const QueryBests& bests) {
    const float k = std::bit_cast<float>(kill.load(std::memory_order_relaxed));
    if (!first && seeds.bucket != kNone && d.sameAsPrevious(i)) {
        // A copy of the previous query (smaller input index, same nearest
        // distance) was killed or offered already.
        bests.d2[i] = bests.d2[i - 1];
        bests.target[i] = bests.target[i - 1];
        ++tally.culled;
        return;
    }
    const Query q = d.query(i);
    Best best;
    if (killedBySeeds(d, i, q, k, seeds, best, stat)) {
        bests.d2[i] = best.d2;
        bests.target[i] = best.target;
        ++tally.culled;
        return;
    }
    ++tally.surviving;
    const bool dead = searchTree(d.t, q, k, best, stat);
    if (best.pos == kNone) {
        tally.lost = true;
        seeds.bucket = kNone;
        return;
    }
    seeds.follow(d.t, best);
    bests.d2[i] = best.d2;
    bests.target[i] = best.target;
    if (dead) return;
    tally.winner.offer(best.d2, uint32_t(d.qKeyed[i]), best.target);
    atomicMax(kill, best.d2);
}

// The pass over all queries, in chunks of consecutive queries; `kill` only grows.
void searchPass(const Direction& d, std::atomic<uint32_t>& kill, PassTally& tally, Progress& progress,
                std::atomic<bool>& lost, const QueryBests& bests) {
    const size_t nq = d.queryCount();
    parallelChunks(nq, kQueryChunk, d.threads, [&](size_t begin, size_t end, int w) {
        if (progress.cancelled()) return;
        ChunkTally chunk{tally.winners[size_t(w)]};
        SearchStats stat;
        Seeds seeds{kNone, kNone, d.firstCell(begin)};
        for (size_t i = begin; i < end; ++i) searchQuery(d, i, i == begin, kill, seeds, chunk, stat, bests);
        if (chunk.lost) lost.store(true, std::memory_order_relaxed);
        tally.winners[size_t(w)] = chunk.winner;
        tally.stats[size_t(w)].bucketsScanned += stat.bucketsScanned;
        tally.culled[size_t(w)] += chunk.culled;
        tally.surviving[size_t(w)] += chunk.surviving;
        progress.queriesDone(end - begin, nq, w);
    });
}

// The winning pair of the pass (largest float distance, smallest query index
// among ties), its distance recomputed in double, and the pass's counters.
Directed witnessOf(const Direction& d, const PassTally& tally) {
    Winner win;
    for (const Winner& w : tally.winners) {
        if (w.query != kNone) win.offer(w.d2, w.query, w.target);
    }
    Directed r;
    r.queryIndex = win.query;
    r.targetIndex = win.target;
    r.queryPoint = d.queries[win.query];
    r.targetPoint = d.targets[win.target];
    const glm::dvec3 diff = glm::dvec3(r.queryPoint) - glm::dvec3(r.targetPoint);
    r.distance = std::sqrt(diff.x * diff.x + diff.y * diff.y + diff.z * diff.z);
    r.counters = passCounters(d, tally.stats);
    for (size_t w = 0; w < tally.culled.size(); ++w) {
        r.counters.culledByNeighbourhood += tally.culled[w];
        r.counters.survivingQueries += tally.surviving[w];
    }
    return r;
}

// The maximum with early break: the lower bound, the pass over all queries,
// the witness.
void earlyBreakDirection(const Direction& d, double boxBound2, Progress& progress, DirectedOutput& out) {
    auto start = Clock::now();
    PassTally tally(d.threads);
    std::atomic<uint32_t> kill{std::bit_cast<uint32_t>(lowerBound(d, boxBound2, tally))};
    out.cullMs = msSince(start);
    progress.report("cull", kCullDone);

    start = Clock::now();
    std::atomic<bool> lost{false};
    // Written by the pass for every query (read only when none was lost or
    // the call cancelled): not zeroed first (core/uninit_vector.hpp; fresh
    // pages zeroed by one thread were ~0.2 s of a torus 10M x 12M call on
    // this repository's 2-core VM).
    UninitVector<float> bestD2;
    UninitVector<uint32_t> bestTarget;
    bestD2.resize(d.queryCount());
    bestTarget.resize(d.queryCount());
    searchPass(d, kill, tally, progress, lost, QueryBests{bestD2.data(), bestTarget.data()});
    out.searchMs = msSince(start);
    out.lostQuery = lost.load();
    out.cancelled = progress.cancelled();
    if (out.cancelled) return;
    progress.report("refine", kSearchDone);

    start = Clock::now();
    out.directed = witnessOf(d, tally);
    if (out.lostQuery) return;
    // The band: every query whose best lies within 2e of the maximum.
    float hf2 = -1.0f;
    for (const Winner& w : tally.winners) hf2 = std::max(hf2, w.d2);
    std::vector<core::BandQuery> band;
    const double threshold2 = core::bandThreshold2(hf2, slackOf(d));
    for (size_t i = 0; i < d.queryCount(); ++i)
        if (double(bestD2[i]) >= threshold2) band.push_back({uint32_t(d.qKeyed[i]), bestTarget[i]});
    out.band = bandOf(d, std::move(band), std::sqrt(double(hf2)));
    out.refineMs = msSince(start);
    proveDirection(d, out);
    progress.report("refine", 1.0);
}

DirectedOutput directedHausdorff(const CpuSet& querySet, const CpuSet& targetSet, int threads,
                                 PerPoint* perPoint, Progress& progress, float kill2) {
    DirectedOutput out;
    progress.report("index", 0.0);
    const auto start = Clock::now();
    const TargetIndex& t = targetSet.targetIndex(threads);
    const SetOrder& qOrder = querySet.order;
    const QueryKeys keys = keyQueries(qOrder, t.grid, targetSet.order.bounds, threads);
    const Direction d{querySet.points, targetSet.points, qOrder.x,      qOrder.y,
                      qOrder.z,        qOrder.keyed,     keys.key,      t,
                      querySet.scale,  threads,          qOrder.bounds, targetSet.order.bounds};
    out.indexMs = msSince(start);
    progress.report("index", kIndexDone);
    if (perPoint != nullptr) {
        perPointDirection(d, *perPoint, progress, out, kill2);
    } else {
        earlyBreakDirection(d, keys.farthest2, progress, out);
    }
    return out;
}

// The shared scaling rule (core::exactScale) over both sets.
double chooseScale(std::span<const glm::vec3> a, std::span<const glm::vec3> b, int threads) {
    return core::exactScale(std::max(core::largestMagnitude(a, threads), core::largestMagnitude(b, threads)));
}

// One direction into `r` (its witness, per-point array and stage times), or
// why it has no result; with a floor, its queries above it into `above`.
std::optional<Error> runDirection(const CpuSet& q, const CpuSet& t, int threads, Progress& progress,
                                  PerPoint* perPoint, Directed& into, core::DirectionBand& band,
                                  Timings& timings, float kill2,
                                  std::optional<std::vector<detail::QueryNearest>>& above) {
    DirectedOutput o = directedHausdorff(q, t, threads, perPoint, progress, kill2);
    timings.index += o.indexMs;
    timings.cull += o.cullMs;
    timings.search += o.searchMs;
    timings.refine += o.refineMs;
    timings.certificate += o.certificateMs;
    if (o.cancelled) return Error{ErrorCode::kCancelled, "the call was cancelled (CallOptions::cancel)"};
    if (o.lostQuery) return Error{ErrorCode::kInternal, "CPU backend: a query found no target"};
    into = o.directed;
    band = o.band;
    above = std::move(o.above);
    return std::nullopt;
}

}  // namespace

const TargetIndex& CpuSet::targetIndex(int threads) const {
    std::call_once(m_indexOnce, [&] { m_index = buildTargetIndex(scale, order, threads); });
    return m_index;
}

uint64_t CpuSet::hostBytes() const {
    auto bytes = [](const auto& v) { return uint64_t(v.capacity()) * sizeof(v[0]); };
    uint64_t sum =
        bytes(order.keyed) + bytes(order.x) + bytes(order.y) + bytes(order.z) + bytes(order.identical);
    const TargetIndex& t = m_index;
    sum += bytes(t.keptX) + bytes(t.keptY) + bytes(t.keptZ) + bytes(t.original) + bytes(t.bucketOf) +
           bytes(t.cellKey) + bytes(t.cellFirst) + bytes(t.cellLo) + bytes(t.cellHi) + bytes(t.bucketFirst);
    for (const BoxLevel& level : t.levels) sum += bytes(level.boxes);
    return sum;
}

std::shared_ptr<CpuSet> prepareCpuSet(std::span<const glm::vec3> points, double scale, int bits,
                                      int threads) {
    auto set = std::make_shared<CpuSet>();
    set->points = points;
    set->scale = scale;
    set->order = orderSet(points, scale, bits, resolveThreads(threads));
    return set;
}

Result<HausdorffResult> cpuHausdorff(const CpuSet& a, const CpuSet& b, const CallOptions& options,
                                     int threadCount, const core::PerPointFloor& floor) {
    const auto start = Clock::now();
    HausdorffResult r;
    r.backend = Backend::kCpu;
    r.device = "cpu";
    r.directedOnly = options.directedOnly;
    const int threads = resolveThreads(threadCount);
    const bool perPoint = options.perPointDistances;
    Progress first(options, 0.0, options.directedOnly ? 1.0 : 0.5);
    auto material = std::make_shared<detail::ProofMaterial>();
    const core::PerPointFloor none;
    const core::PerPointFloor& floors = perPoint ? floor : none;
    auto above = std::make_shared<detail::AboveFloor>();
    if (auto e = runDirection(a, b, threads, first, perPoint ? &r.aNearest : nullptr, r.aToB, material->aToB,
                              r.timings, floors.kill2(0), above->of[0]))
        return *e;
    r.hausdorff = r.aToB.distance;
    if (!options.directedOnly) {
        Progress second(options, 0.5, 0.5);
        if (auto e = runDirection(b, a, threads, second, perPoint ? &r.bNearest : nullptr, r.bToA,
                                  material->bToA, r.timings, floors.kill2(1), above->of[1]))
            return *e;
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
    }
    if (floors.any()) {  // no witness: the queries above the floors (the arrays of a direction without one)
        r.hausdorff = 0.0;
        r.aboveFloor = std::move(above);
    } else {
        r.proofMaterial = std::move(material);
    }
    r.timings.total = msSince(start);
    return r;
}

Result<HausdorffResult> cpuHausdorff(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double scale,
                                     const Options& options, const core::PerPointFloor& floor) {
    if (a.empty() || b.empty()) {
        return Error{ErrorCode::kInvalidArgument, "cpuHausdorff: empty point set (H is undefined)"};
    }
    const auto start = Clock::now();
    // Each set ordered once: the layout of its index and its query order.
    const std::shared_ptr<CpuSet> setA = prepareCpuSet(a, scale, options.bits, options.threads);
    const std::shared_ptr<CpuSet> setB = prepareCpuSet(b, scale, options.bits, options.threads);
    const double orderMs = msSince(start);
    Result<HausdorffResult> r = cpuHausdorff(*setA, *setB, options, options.threads, floor);
    if (!r) return r;
    r->timings.index += orderMs;
    r->timings.total = msSince(start);
    return r;
}

Result<HausdorffResult> cpuHausdorff(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                     const Options& options) {
    const auto start = Clock::now();
    const double scale = a.empty() || b.empty() ? 1.0 : chooseScale(a, b, options.threads);
    const double scaleMs = msSince(start);  // a pass over the points: the index stage's, as the orders
    Result<HausdorffResult> r = cpuHausdorff(a, b, scale, options);
    if (!r) return r;
    r->timings.index += scaleMs;
    r->timings.total = msSince(start);
    return r;
}

}  // namespace rthdist::cpu
