// Shared between C++ (src/gpu_algo) and GLSL (shaders/): push-constant
// blocks, record layouts and constants. Every buffer is reached through its
// device address (GL_EXT_buffer_reference), so shaders need no descriptor sets
// except the TLAS of the ray-tracing stages (set 0, binding 0).
#ifndef RTHDIST_SHARED_H
#define RTHDIST_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace rthdist::shared {
using uint = uint32_t;
struct vec3f {
    float x, y, z;
};
#define RTHDIST_VEC3 vec3f
#else
#define RTHDIST_VEC3 vec3
#endif

// Workgroup size of every 1-D compute dispatch.
#define RTHDIST_WG 128
#define RTHDIST_TAIL_WG 64  // tail_scan.comp: threads per open query
// Elements per scan block: one workgroup of RTHDIST_SCAN_WG threads, each
// scanning RTHDIST_SCAN_PER_THREAD consecutive elements serially (few
// barriers: they dominate on lavapipe).
#define RTHDIST_SCAN_WG 256
#define RTHDIST_SCAN_PER_THREAD 16
#define RTHDIST_SCAN_BLOCK 4096

// A host-visible counter block (byte offsets; one per index build or
// direction in flight, zeroed by the host before the submissions that count
// into it; RTHDIST_CTR_BYTES apart).
#define RTHDIST_CTR_ACTIVE 0          // uint: compact.comp, queries entering the search
#define RTHDIST_CTR_MAX_COUNT 4       // uint: cell_build, points of the largest cell that can split
#define RTHDIST_CTR_NEXT_ACTIVE 8     // uint: resolve.comp, queries going on
#define RTHDIST_CTR_CELLS 12          // uint: cell_build/coarsen, cells written
#define RTHDIST_CTR_MAX_PACKED 16     // uint64: (bits of h^2 << 32) | query slot
#define RTHDIST_CTR_PAIRS 24          // uint64: candidate pairs appended (64-bit: cannot wrap)
#define RTHDIST_CTR_CHECK_SUM 32      // uint64: self-check, sum of original indices
#define RTHDIST_CTR_CHECK_BAD 40      // uint64: self-check, records that broke an invariant
#define RTHDIST_CTR_MIN_EDGE 48       // float bits: leaf_slots, the narrowest sub-cell edge of a split
#define RTHDIST_CTR_LARGE_CELLS 52    // uint: cell_build, 1 when a cell needs the parallel box
#define RTHDIST_CTR_SEARCH_ACTIVE 56  // uint: queries the radius in flight searches (search_advance.comp)
#define RTHDIST_CTR_SEARCH_OPEN \
    60                               // uint: queries going on after the last radius that searched
                                     // (search_advance.comp; the host's "still open")
#define RTHDIST_CTR_READBACK 64      // host read-back area after the counters
#define RTHDIST_CTR_INGEST 1152      // IngestSummary: ingest.comp, one set's bounds and first bad point
#define RTHDIST_CTR_INGEST64 1184    // IngestSummary64: ingest_f64.comp, one device view's box in double
#define RTHDIST_CTR_KILL_SLACK 1272  // float: the certificate's slack e (deadThreshold kills below its band)
#define RTHDIST_CTR_KILL_FLOOR \
    1276  // float: a per-point call's kill threshold (core/per_point_floor.hpp; 0: none)
#define RTHDIST_CTR_SEARCH_LOG 1280  // SearchLogEntry[RTHDIST_SEARCH_LOG_MAX]: the radii of one submission
#define RTHDIST_CTR_SEARCH_ARGS \
    1600  // uint[3] groups of the search and resolve, uint[3] rays (search_advance.comp)
#define RTHDIST_CTR_CHECK_ARGS \
    1624                        // uint[3] groups of the self-check behind search radii (search_advance.comp)
#define RTHDIST_CTR_PROBE 1536  // uint[RTHDIST_PROBE_LEVELS + 1]: probe_levels.comp, distinct cells per level
// A per-point call with a floor, handed back sparse (check_queries.comp): the
// queries above the floor appended as uvec2 (original index, nearest) to the
// list at ABOVE_OUT (0: none) while they fit ABOVE_CAPACITY; ABOVE_COUNT
// goes on past it (overflow: the host reads the dense array instead).
#define RTHDIST_CTR_ABOVE_COUNT 1640     // uint
#define RTHDIST_CTR_ABOVE_CAPACITY 1644  // uint
#define RTHDIST_CTR_ABOVE_OUT 1648       // uint64
#define RTHDIST_CTR_BYTES 2048
// Radii of the candidate search recorded in one submission, at most.
#define RTHDIST_SEARCH_LOG_MAX 16

// PerPoint::nearest of a query a per-point call's floor stopped
// (core::kBelowFloor; UINT32_MAX is the fill of "never written").
#define RTHDIST_BELOW_FLOOR 0xfffffffeu

// Query status values.
#define RTHDIST_OPEN 0u
#define RTHDIST_EXACT 1u
#define RTHDIST_DEAD 2u
#define RTHDIST_RETRY 3u  // pairs were dropped (buffer full): redo at the same radius

// One occupied cell: [first, first+count) in the cell-sorted points; lo/hi is
// the tight box of its points. points[first] is the cell's representative.
struct Cell {
    RTHDIST_VEC3 lo;
    uint first;
    RTHDIST_VEC3 hi;
    uint count;
};

// Grid of one index: origin and inverse cell size are rounded from the host's
// double values; bounds used for exactness carry an epsilon (see shaders).
struct GridParams {
    float originX, originY, originZ;
    float cellSize;
    float invCellSize;
    uint bits;
    uint cellsPerAxis;
    uint pad0;
};

// cell_keys.comp: key per point, histogram into the dense table.
struct KeysPush {
    uint64_t points;  // vec4[n] input (xyz, w unused)
    uint64_t keys;    // uint per thread out (spread: spreadThreads(n) of them, else n)
    uint64_t dense;   // uint[2^(3 bits)] histogram (zeroed)
    GridParams grid;
    uint n;
    uint spread;  // 1: thread t takes point spreadItem(t, n) (common.glsl), else point t
};

// ingest.comp: the caller's points (x, y, z floats at source + i * stride, in
// host-visible or device memory) into vec4 records, with their bounds and
// the first point that is not finite.
struct IngestPush {
    uint64_t source;
    uint64_t points;   // vec4[n] out: xyz, w = 0
    uint64_t summary;  // IngestSummary, initialised by the host
    uint n;
    uint stride;  // bytes, a multiple of 4, >= 12
};

// What ingest.comp reports of a set: the bounds of its finite points as
// order-preserving bits (orderedBits in common.glsl; lo starts at 0xffffffff,
// hi at 0) and the smallest index of a non-finite point (0xffffffff: none).
struct IngestSummary {
    uint lo[3];
    uint hi[3];
    uint firstBad;
    uint pad;
};

// ingest_f64.comp: a device view of the embedder's points (three floats or
// doubles at source + i * stride) in two passes. Mode 0 reduces its box in
// double into an IngestSummary64; mode 1 writes float(p - origin), computed
// in double, into vec4 records and their float bounds into an IngestSummary.
// The origin travels as the bits of three doubles (no double type here:
// every shader includes this header, and only this one may need Float64).
struct IngestDevicePush {
    uint64_t source;
    uint64_t points;     // vec4[n] out (mode 1)
    uint64_t summary;    // IngestSummary64 (mode 0) or IngestSummary (mode 1), initialised by the host
    uint64_t origin[3];  // double bits (mode 1)
    uint n;
    uint stride;    // bytes, a multiple of the scalar size
    uint isDouble;  // 1: three doubles per point, 0: three floats
    uint mode;
};

// What mode 0 of ingest_f64.comp reports of a device view: its box in double
// as order-preserving bits (lo starts at ~0, hi at 0), the smallest index of
// a non-finite point (0xffffffff: none), and whether a coordinate is not a
// float32 value (notFloat != 0).
struct IngestSummary64 {
    uint64_t lo[3];
    uint64_t hi[3];
    uint firstBad;
    uint notFloat;
};

// scan_block.comp / scan_add.comp: exclusive scan of uint[n] in place.
struct ScanPush {
    uint64_t data;
    uint64_t blockSums;
    uint n;
};

// scatter.comp: counting-sort scatter; dense[key] ends as the cell's end.
struct ScatterPush {
    uint64_t points;      // vec4[n] input
    uint64_t keys;        // uint per thread, as cell_keys.comp wrote them
    uint64_t dense;       // uint[] starts in, ends out
    uint64_t sorted;      // vec4[n] out: xyz, w = original index (float bits)
    uint64_t sortedKeys;  // uint[n] out
    uint n;
    uint spread;  // as KeysPush::spread (the same order as the keys pass)
};

// cell_heads.comp writes flags (1 where a cell starts); after a scan
// cell_build.comp writes one Cell per head (the box of a large cell comes from
// cell_bounds.comp and cell_bounds_fix.comp).
struct CellsPush {
    uint64_t sorted;
    uint64_t sortedKeys;
    uint64_t flags;       // uint[n]: head flags, scanned in place between passes
    uint64_t dense;       // cell ends by key
    uint64_t cells;       // Cell[] out
    uint64_t numCells;    // uint[1] out
    uint64_t maxCount;    // uint[1]: atomicMax of the count of every cell that can split
                          // (more than one distinct point)
    uint64_t boundsU;     // uint[6 * cells]: order-preserving bits of a large cell's box
                          // (lo xyz, hi xyz), reduced with atomics by cell_bounds.comp
    uint64_t largeCells;  // uint[1]: set by cell_build when any cell is large (zeroed by
                          // the host): the parallel box passes return at once otherwise
    uint n;
    uint cellCapacity;  // cells the Cell buffer can hold (cell_bounds_fix dispatch)
};

// A cell of more than this many points gets its tight box from a parallel
// reduction (cell_bounds.comp) instead of its head thread's serial loop.
#define RTHDIST_SERIAL_BOX 64u
// Leaves of a split index hold at most this many points unless all are one
// point; cell_build reports (maxCount) only cells larger than this, so the
// common small cells cost no atomic.
#define RTHDIST_LEAF_MAX 32u

// Leaf splitting (density-robust index): a cell holding more than `leafMax`
// points that are not all identical is cut into 8^k sub-cells of its own tight
// box, k from its count, and its points are re-sorted by sub-cell (a counting
// sort over slots: one slot per unsplit cell, 8^k per split one). Rounds repeat
// until no cell that can split holds more than leafMax points.
// leaf_slots.comp: slots per cell (scanned in place into each cell's first slot).
// leaf_keys.comp: slot of every sorted point, histogram into `dense`.
// leaf_scatter.comp: counting-sort scatter by slot (points, grid keys, slots).
struct SplitPush {
    uint64_t cells;        // Cell[numCells] of the current order
    uint64_t slotBase;     // uint[numCells]: slots, then (scanned) the first slot
    uint64_t sorted;       // vec4[n] in (w = original index bits)
    uint64_t gridKeys;     // uint[n] in: grid key of every sorted point
    uint64_t dense;        // uint[slots] histogram / starts / ends
    uint64_t slotKeys;     // uint[n]: leaf_keys out, leaf_scatter in
    uint64_t outSorted;    // vec4[n] out (leaf_scatter)
    uint64_t outGridKeys;  // uint[n] out (leaf_scatter)
    uint64_t outSlotKeys;  // uint[n] out (leaf_scatter)
    uint64_t minEdge;      // uint[1]: atomicMin of the float bits of split sub-cell edges
    uint numCells;
    uint n;
    uint leafMax;
};

// Per-query search state (one per query of a direction).
struct QueryState {
    uint64_t best;  // (bits of squared distance << 32) | target original index
    float rLo;      // every target point within rLo of the query has been scanned
    uint status;    // RTHDIST_OPEN / EXACT / DEAD / RETRY
};

// cull.comp: exact NN within the 3x3x3 block of cells around each query.
struct CullPush {
    uint64_t queries;    // vec4[nq] sorted queries (w = original index bits)
    uint64_t targets;    // vec4[nt] cell-sorted targets
    uint64_t dense;      // target cell ends by key
    uint64_t state;      // QueryState[nq]
    uint64_t maxPacked;  // uint64[1]: (bits of d^2 << 32) | query original index
    GridParams grid;
    uint nq;
    float lowerBound2;  // squared lower bound of h without witness
    float epsilon;      // absolute slack for cell-geometry bounds (object units)
    uint blockRLo;      // 1: rLo = distance to the block's faces (search on fine
                        // cells); 0: rLo = 0 (search cells are coarser, so the
                        // block does not cover whole search cells)
    uint scanMax;       // a cell of more points is not scanned (only its first point):
                        // the query then cannot be settled by this pass
    uint mutant;        // tests only (core/search_mutant.hpp): 1 = skip the query's own cell
    uint cellTests;     // box tests (leaf groups and leaves) of one crowded cell at most:
                        // past them the cell is not scanned whole
    uint pad0;
    uint64_t leaves;      // Cell[] (a split index's cells), 0: not split
    uint64_t groupFirst;  // uint per key: the first leaf group of an occupied crowded cell
    uint64_t groups;      // LeafGroup[]
};

// leaf_first.comp: the first leaf of each grid cell of a split index.
struct LeafFirstPush {
    uint64_t leaves;      // Cell[numLeaves]
    uint64_t sortedKeys;  // grid key per sorted point
    uint64_t leafFirst;   // uint per grid key (out)
    uint numLeaves;
    uint pad0;
};

// Leaf groups of a split index (leaf_groups.comp): the leaves of each crowded
// grid cell (more than kCrowdedCell points) in runs of at most groupLeaves,
// each run's box the union of its leaves' boxes, so that the neighbourhood
// pass tests a run's box before its leaves'. A cell's groups are
// consecutive; the last one has RTHDIST_GROUP_LAST set in `leaves`.
struct LeafGroup {
    RTHDIST_VEC3 lo;
    uint firstLeaf;
    RTHDIST_VEC3 hi;
    uint leaves;  // leaf count, | RTHDIST_GROUP_LAST on its cell's last group
};
#define RTHDIST_GROUP_LAST 0x80000000u
#define RTHDIST_GROUP_COUNT 0x7fffffffu

// mode 0: a head flag per leaf (the first leaf of every groupLeaves of a
// crowded cell, counted from its first leaf; firsts = leafFirst); the flags
// are scanned (exclusive) into group indices; mode 1: the groups; mode 2:
// firsts[key] = the cell's first group (overwrites leafFirst, which modes 0
// and 1 read).
struct LeafGroupPush {
    uint64_t leaves;      // Cell[numLeaves]
    uint64_t sortedKeys;  // grid key per sorted point
    uint64_t dense;       // grid cell ends by key
    uint64_t firsts;      // uint per grid key: first leaf (modes 0, 1), first group (mode 2 out)
    uint64_t flags;       // uint[numLeaves]: head flags, then their exclusive scan
    uint64_t groups;      // LeafGroup[] out (mode 1)
    uint numLeaves;
    uint groupLeaves;  // leaves per group at most (>= 1)
    uint crowded;      // a grid cell of more points has groups (kCrowdedCell)
    uint mode;
};

// coarsen.comp: search cells of level j (edge s * 2^j) from those of level
// j - 1 (runs sharing fine key >> 3j). mode 0 writes head flags, mode 1 the cells.
struct CoarsenPush {
    uint64_t fineCells;
    uint64_t sortedKeys;      // fine key of every sorted point
    uint64_t flags;           // uint[numFine]: head flags, scanned between the modes
    uint64_t coarseCells;     // Cell[] out
    uint64_t numCoarse;       // uint[1] out
    uint64_t finerFineFirst;  // uint per finer cell: its first level-0 cell (unused at level 1)
    uint64_t fineFirst;       // uint per coarse cell out: its first level-0 cell
    uint numFine;
    uint mode;
    uint shift;  // 3 * level: the parent key is a point's fine key >> shift
};

// compact.comp: appends OPEN queries whose best is not below the threshold.
struct CompactPush {
    uint64_t state;
    uint64_t activeList;  // uint[] out: query slots
    uint64_t counters;    // the counter block (RTHDIST_CTR_ACTIVE)
    uint64_t maxPacked;
    uint nq;
    float lowerBound2;
};

// grow_boxes.comp: AABB per cell = tight box grown by radius (+ epsilon).
// The epsilon is per box, relative to the box's own magnitude: a box near the
// origin needs far less slack than the largest coordinate of the set.
struct BoxesPush {
    uint64_t cells;
    uint64_t aabbs;  // VkAabbPositionsKHR[numCells]
    uint numCells;
    float grow;    // the radius (plus its own rounding slack)
    float relEps;  // slack per unit of the box's largest |coordinate| + grow
    float absEps;  // absolute slack (the grid's rounding)
};

// search (ray query compute or raygen+intersection): candidate cells.
struct SearchPush {
    uint64_t queries;
    uint64_t targets;
    uint64_t cells;
    uint64_t state;
    uint64_t activeList;  // uint[numActive]
    uint64_t pairs;       // uvec2[capacity]: (active slot, cell)
    uint64_t counters;    // the counter block (RTHDIST_CTR_PAIRS)
    uint64_t maxPacked;
    uint numActive;  // slots dispatched: at least RTHDIST_CTR_SEARCH_ACTIVE, the ones searched
    uint pairCapacity;
    float radius;  // R: cells with box distance <= R are candidates
    float lowerBound2;
    float rayTMax;
    uint skipScanned;  // 1: cells within rLo were scanned at this same level
    uint slotBase;     // rt-pipeline: first active slot of this trace (traces are split by
                       // maxRayDispatchInvocationCount); 0 for the ray-query dispatch
    uint retryStride;  // > 1: only queries qi with qi % retryStride == retryPhase are searched,
    uint retryPhase;   // the others marked RETRY (RadiusSchedule's retry classes)
};

// Query slots the self-check samples: all of n <= RTHDIST_CHECK_SAMPLES,
// else slot k = (n - 1) * k / (RTHDIST_CHECK_SAMPLES - 1) (sampleSlots).
#define RTHDIST_CHECK_SAMPLES 32u

// check_index.comp / check_queries.comp: the self-check (every record visited
// once, violations counted at RTHDIST_CTR_CHECK_BAD).
struct CheckPush {
    uint64_t sorted;      // vec4[n] cell-sorted points (w = original index)
    uint64_t sortedKeys;  // check_index: uint[n]
    uint64_t state;       // check_queries: QueryState[n]
    uint64_t counters;    // the counter block
    GridParams grid;      // check_index: the index's grid
    uint n;
    uint perPoint;        // check_queries: 1 = every query must be EXACT
    uint64_t witnessOut;  // check_queries: the witness query's sorted record and state (32 bytes)
    uint afterCull;       // check_queries recorded behind the cull: nothing to do when queries
                          // survived (RTHDIST_CTR_ACTIVE > 0): they are checked after the search
    uint samples;         // check_queries: sampled records written before the witness's (32
                          // bytes each, slots by the rule of RTHDIST_CHECK_SAMPLES)
    uint64_t nearestOut;  // check_queries, per-point calls: uint[n], each query's nearest target
                          // at the query's original index (0: not written)
    uint64_t bandOut;     // check_queries: the certificate's band (core/certificate.hpp): uint count,
                          // uint pad, then uvec2 (query, best target) original indices (0: none)
    uint bandCapacity;    // entries bandOut holds (the count goes on past it: overflow)
    float bandSlack;      // e of the certificate, search units (rounded up)
};

// cert_witness.comp: the certificate's brute force of the witness query
// (the slot in the low half of the maximum), recorded with the final
// self-check: every target within (sqrt(max) + 4e)^2, rounded up, which holds
// every target within the host's bound for it (U + 3e, certificate_pass.cpp).
struct CertWitnessPush {
    uint64_t targets;   // vec4[n] the target set's points (w = original index)
    uint64_t queries;   // vec4[queryCount] the query set's cell-sorted points (w = original index)
    uint64_t counters;  // the counter block (RTHDIST_CTR_MAX_PACKED, RTHDIST_CTR_ACTIVE)
    uint64_t found;     // uint ran (1), uint query (original index), uint count, uint pad, then
                        // uint[capacity] targets (original indices)
    uint n;
    uint queryCount;
    uint capacity;   // targets `found` holds (the count goes on past it: overflow)
    float slack;     // e of the certificate, search units (rounded up)
    uint afterCull;  // as CheckPush::afterCull: nothing to do when queries survived the cull
    uint pad0, pad1, pad2;
};

// cert_scan.comp: the certificate's brute force over every target of a
// direction for up to RTHDIST_CERT_ENTRIES band queries at once.
#define RTHDIST_CERT_ENTRIES 64
struct CertScanPush {
    uint64_t targets;  // vec4[n] the target set's points (w = original index)
    uint64_t entries;  // vec4[entryCount]: a band query (search units) and its squared bound
    uint64_t found;    // uint count, uint pad, then uvec2 (entry, target original index)
    uint n;
    uint entryCount;
    uint capacity;  // candidates `found` holds (the count goes on past it: overflow)
    uint mode;      // 0: append every target within an entry's bound; 1: each entry's float nearest
                    // (squared distance bits << 32 | target) by atomicMin into uint64 `found`[entry]
};

// refine.comp: exact scan of the candidate pairs' cells.
struct RefinePush {
    uint64_t queries;
    uint64_t targets;
    uint64_t cells;
    uint64_t state;
    uint64_t activeList;
    uint64_t pairs;
    uint64_t counters;
    uint64_t maxPacked;
    uint64_t fineCells;  // level-0 cells: a search cell is scanned through them
    uint64_t fineFirst;  // uint per search cell: its first level-0 cell; 0 when the
                         // search cells are the level-0 cells themselves
    uint pairCapacity;
    float lowerBound2;
    uint numSearchCells;
    uint numFineCells;
    uint mutant;  // tests only (core/search_mutant.hpp): 1 = drop every third pair
};

// tail_scan.comp: every open query of a direction scans every search cell
// of one level (the candidate search's far tail), one workgroup of
// RTHDIST_TAIL_WG threads per query (numActive groups).
struct TailScanPush {
    uint64_t queries;
    uint64_t targets;
    uint64_t cells;  // the level's search cells
    uint64_t state;
    uint64_t activeList;  // the open queries' slots
    uint64_t maxPacked;
    uint64_t fineCells;  // level-0 cells: a search cell is scanned through them
    uint64_t fineFirst;  // uint per search cell: its first level-0 cell; 0 when the
                         // search cells are the level-0 cells themselves
    uint numActive;
    float lowerBound2;
    uint numSearchCells;
    uint numFineCells;
};

// sweep_targets.comp: every open query against every target (the search's
// sweep, CandidateSearch::sweepWork). Targets per thread of one item.
#define RTHDIST_SWEEP_PER_THREAD 32u
struct SweepPush {
    uint64_t queries;     // vec4 sorted queries
    uint64_t targets;     // vec4[n] the targets (w = original index)
    uint64_t state;       // QueryState per query
    uint64_t activeList;  // the open queries' slots
    uint n;               // targets
    uint numActive;       // open queries (slots of activeList)
};

// sample_gather.comp: records j * stride (j < count) of `points` (vec4) into
// `gathered` (float[3 count]), the bit count's sample of a device-input set.
struct SampleGatherPush {
    uint64_t points;
    uint64_t gathered;  // float[3 count] out
    uint count;
    uint stride;
};

// The small-pair batch (batch_nearest.comp, batch_witness.comp): pairs of a
// computeBatch small enough for an exact scan of every target by every query,
// all directions of all pairs in one submission. One direction of one pair:
struct BatchDirection {
    uint64_t queries;  // vec4 records of the query set (xyz searched, w = input index bits)
    uint64_t targets;  // the same of the target set
    uint64_t nearest;  // uint per query, by input index (out): its nearest target's input index
    float queryScale;  // powers of two into the pair's frame (exact multiplications)
    float targetScale;
    uint queryCount;
    uint targetCount;
    uint step;          // the scan visits target (j * step) mod targetCount: step coprime with it
    uint sampleStride;  // the seed pass scans queries 0, stride, 2 stride, ... (RTHDIST_WG of them)
};
#define RTHDIST_BATCH_DIRECTION_BYTES 48

// batch_nearest.comp: one workgroup per chunk (uvec2: direction, first query)
// of RTHDIST_WG queries. A query that finished its scan puts (bits of its
// nearest distance^2 << 32) | its input index into maxPacked[direction]
// (atomicMax) and its nearest target into `nearest`; with earlyBreak, a query
// stops once it has a target at most maxPacked's distance away (it cannot
// raise h). seed (earlyBreak 0): chunk (direction, 0) scans the direction's sample queries
// (the first lower bound of h, with its witness).
struct BatchNearestPush {
    uint64_t directions;  // BatchDirection[]
    uint64_t chunks;      // uvec2 per workgroup
    uint64_t maxPacked;   // uint64 per direction, zeroed before the seed pass
    uint earlyBreak;      // 0: per-point distances (every query scans every target)
    uint seed;
};

// batch_witness.comp: per direction, uvec4 (query input index, its nearest
// target's input index, bits of h^2, 0) from maxPacked and `nearest`.
struct BatchWitnessPush {
    uint64_t directions;
    uint64_t maxPacked;
    uint64_t witnesses;  // uvec4 per direction (out)
    uint count;
};

// refine_args.comp: VkDispatchIndirectCommand for refine.comp from the pair
// counter (groups of RTHDIST_WG pairs, at most maxGroups).
struct RefineArgsPush {
    uint64_t counters;  // the counter block (RTHDIST_CTR_PAIRS)
    uint64_t args;      // uint[3] out
    uint pairCapacity;
    uint maxGroups;
};

// resolve.comp: classifies active queries after an iteration, compacts the rest.
struct ResolvePush {
    uint64_t state;
    uint64_t activeList;  // in
    uint64_t nextActive;  // out
    uint64_t counters;    // the counter block (RTHDIST_CTR_NEXT_ACTIVE)
    uint64_t maxPacked;
    uint numActive;  // slots dispatched: at least RTHDIST_CTR_SEARCH_ACTIVE, the ones resolved
    float radius;
    float lowerBound2;
    uint sameLevel;  // 1: the radius before searched this level (a RETRY query keeps its rLo), else 0
};

// probe_levels.comp: the automatic bit count's probe on the device (the same
// sample, keys and counts as core::chooseBitsFromSample on the host): the
// sample's 10-bit probe cell keys, each level's distinct cells counted by
// inserting the key's top 3k bits into a hash table of that level.
#define RTHDIST_PROBE_LEVELS 8      // levels 1..8 (core::kMaxBits)
#define RTHDIST_PROBE_SLOT_BITS 17  // slots per level's table: twice the largest sample
struct ProbeLevelsPush {
    uint64_t points;     // vec4 records of the ingested set
    uint64_t tables;     // uint[RTHDIST_PROBE_LEVELS << RTHDIST_PROBE_SLOT_BITS], zeroed (0: empty)
    uint64_t counts;     // uint[RTHDIST_PROBE_LEVELS + 1] (RTHDIST_CTR_PROBE), zeroed
    uint64_t origin[3];  // double bits: the probe's origin (the box's low corner)
    uint64_t perLength;  // double bits: probe cells per unit length
    uint count;          // sampled records: record j * stride for j < count
    uint stride;
};

// search_advance.comp: between two radii of one submission, the radius just
// run is logged (entry `iteration` of RTHDIST_CTR_SEARCH_LOG) and the next
// one set up: its queries are the ones going on, or none once the pair buffer
// overflowed (the host resumes from the logged radius with more room).
struct SearchLogEntry {
    uint searched;   // queries this radius searched
    uint goingOn;    // queries going on
    uint64_t pairs;  // (query, cell) pairs the rays appended (some lost when > capacity)
};
struct SearchAdvancePush {
    uint64_t counters;  // the counter block
    uint iteration;     // the log entry of the radius just run
    uint pairCapacity;
    uint checkGroups;  // groups of the self-check behind the radii (0: none recorded)
    uint pad0;
};

#ifdef __cplusplus
// The counters of a block as the host reads and zeroes them: one field per
// RTHDIST_CTR_* offset the shaders use, each offset asserted here.
struct CounterFields {
    uint active;
    uint maxCount;
    uint nextActive;
    uint cells;
    uint64_t maxPacked;
    uint64_t pairs;
    uint64_t checkSum;
    uint64_t checkBad;
    uint minEdge;  // float bits
    uint largeCells;
    uint searchActive;
    uint searchOpen;
};
static_assert(offsetof(CounterFields, active) == RTHDIST_CTR_ACTIVE);
static_assert(offsetof(CounterFields, maxCount) == RTHDIST_CTR_MAX_COUNT);
static_assert(offsetof(CounterFields, nextActive) == RTHDIST_CTR_NEXT_ACTIVE);
static_assert(offsetof(CounterFields, cells) == RTHDIST_CTR_CELLS);
static_assert(offsetof(CounterFields, maxPacked) == RTHDIST_CTR_MAX_PACKED);
static_assert(offsetof(CounterFields, pairs) == RTHDIST_CTR_PAIRS);
static_assert(offsetof(CounterFields, checkSum) == RTHDIST_CTR_CHECK_SUM);
static_assert(offsetof(CounterFields, checkBad) == RTHDIST_CTR_CHECK_BAD);
static_assert(offsetof(CounterFields, minEdge) == RTHDIST_CTR_MIN_EDGE);
static_assert(offsetof(CounterFields, largeCells) == RTHDIST_CTR_LARGE_CELLS);
static_assert(offsetof(CounterFields, searchActive) == RTHDIST_CTR_SEARCH_ACTIVE);
static_assert(offsetof(CounterFields, searchOpen) == RTHDIST_CTR_SEARCH_OPEN);
static_assert(sizeof(ProbeLevelsPush) == 64 &&
              RTHDIST_CTR_SEARCH_LOG + RTHDIST_SEARCH_LOG_MAX * 16 <= RTHDIST_CTR_PROBE &&
              RTHDIST_CTR_PROBE + (RTHDIST_PROBE_LEVELS + 1) * 4 <= RTHDIST_CTR_SEARCH_ARGS &&
              RTHDIST_CTR_SEARCH_ARGS + 24 <= RTHDIST_CTR_CHECK_ARGS &&
              RTHDIST_CTR_CHECK_ARGS + 12 <= RTHDIST_CTR_ABOVE_COUNT &&
              RTHDIST_CTR_ABOVE_OUT + 8 <= RTHDIST_CTR_BYTES);
static_assert(sizeof(SearchLogEntry) == 16 && RTHDIST_CTR_INGEST64 + 56 <= RTHDIST_CTR_KILL_SLACK &&
              RTHDIST_CTR_KILL_SLACK + 4 <= RTHDIST_CTR_KILL_FLOOR &&
              RTHDIST_CTR_KILL_FLOOR + 4 <= RTHDIST_CTR_SEARCH_LOG &&
              RTHDIST_CTR_SEARCH_LOG + RTHDIST_SEARCH_LOG_MAX * 16 <= RTHDIST_CTR_BYTES);
static_assert(sizeof(CounterFields) <= RTHDIST_CTR_READBACK);
static_assert(sizeof(TailScanPush) == 80);
static_assert(sizeof(SweepPush) == 40);
static_assert(sizeof(CullPush) <= 128 && sizeof(LeafFirstPush) == 32);
static_assert(sizeof(LeafGroup) == 32 && offsetof(LeafGroup, leaves) == 28 && sizeof(LeafGroupPush) == 64);
static_assert(sizeof(CheckPush) == 112 && offsetof(CheckPush, nearestOut) == 88);
static_assert(sizeof(CertScanPush) == 40);
static_assert(sizeof(CertWitnessPush) == 64);
static_assert(sizeof(IngestDevicePush) == 64 && offsetof(IngestDevicePush, n) == 48);
static_assert(sizeof(BatchDirection) == RTHDIST_BATCH_DIRECTION_BYTES);
static_assert(sizeof(IngestSummary64) == 56 && offsetof(IngestSummary64, firstBad) == 48);

}  // namespace rthdist::shared
#endif
#endif
