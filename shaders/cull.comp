#version 460
#extension GL_GOOGLE_include_directive : require
// Neighbourhood pass (before any ray): exact NN of each query within the
// 3x3x3 block of target cells around its own cell. A target outside the block
// is at least dOut away (distance from q to the block's faces, minus epsilon),
// so a minimum m <= dOut is the exact NN, provided every point of the block
// nearer than m was scanned:
// - the own cell first, then the neighbours; a neighbour whose box (grown by
//   epsilon, as dOut is shrunk) is farther than the running best holds no
//   nearer point and is skipped;
// - a crowded cell (more than scanMax points: a split index's cell) is
//   scanned through its leaf groups (leaf_groups.comp; groupFirst finds the
//   first), each skipped when its box is farther than the running best, and
//   the leaves of the others likewise (a group's box holds its leaves' boxes
//   and float rounding is monotone, so a skipped group's computed distance
//   is at most each of its leaves', at most each of their points':
//   scan_cells.glsl); with no best yet, the cell's first point and then the
//   group nearest to q go first. A cell that needs more than cellTests box
//   tests, or any crowded cell of an index without leaves (copies of one
//   point), contributes what was scanned (its first point at least) and the
//   query is left to the candidate search;
// a minimum of 0 is exact whatever was skipped. A point strictly closer than
// the running maximum kills the query at once (early break, Taha & Hanbury
// 2015).
#include "common.glsl"
#include "scan_cells.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { CullPush pc; };

// The leaves of group `g` not farther than the best; false once the cell's
// box tests (`tests`) would pass `limit`.
bool scanGroup(vec3 q, LeafGroup g, float thr, uint limit, inout uint tests, inout float best, inout uint bestT,
               inout bool dead) {
    uint end = g.firstLeaf + (g.leaves & RTHDIST_GROUP_COUNT);
    for (uint l = g.firstLeaf; l < end && !dead && best > 0.0; ++l) {
        if (tests >= limit) return false;
        ++tests;
        Cell leaf = cellAt(pc.leaves, l).v;
        if (boxDist2(q, leaf.lo, leaf.hi) > best) continue;
        scanCellPoints(q, leaf, pc.targets, thr, best, bestT, dead);  // the refinement's scan of a cell
    }
    return true;
}

// A crowded cell of a split index (its points from `start`): its groups, each
// skipped when its box is farther than the best, and the leaves of the
// others. With no best yet, the cell's first point is measured first (where
// the running maximum is large, a cluster seen from afar, it kills the query
// at once), then the group nearest to q (the first whose box holds q) is
// scanned, so that the others meet a small best. false: the cell was not
// scanned whole (its groups and leaves need more than pc.cellTests box
// tests; the nearest group among those tested is still scanned).
bool scanCrowdedCell(vec3 q, uint key, uint start, float thr, inout float best, inout uint bestT,
                     inout bool dead) {
    const float kInf = uintBitsToFloat(0x7f800000u);
    const uint kNone = 0xffffffffu;
    uint g0 = uintAt(pc.groupFirst, key).v;
    uint tests = 0u;
    uint first = kNone;  // the group scanned before the others
    if (best == kInf) {
        vec4 tv = vec4At(pc.targets, start).v;
        best = dist2(q, tv.xyz);
        bestT = floatBitsToUint(tv.w);
        if (best < thr) {
            dead = true;
            return true;
        }
        float nearest = kInf;
        bool whole = true;
        for (uint g = g0;; ++g) {
            if (tests == pc.cellTests) {
                whole = false;
                break;
            }
            ++tests;
            LeafGroup grp = groupAt(pc.groups, g).v;
            float d2 = boxDist2(q, grp.lo, grp.hi);
            if (first == kNone || d2 < nearest) {
                nearest = d2;
                first = g;
            }
            if (d2 == 0.0 || (grp.leaves & RTHDIST_GROUP_LAST) != 0u) break;
        }
        if (!whole) {
            if (first != kNone) scanGroup(q, groupAt(pc.groups, first).v, thr, kNone, tests, best, bestT, dead);
            return false;
        }
        if (!scanGroup(q, groupAt(pc.groups, first).v, thr, pc.cellTests, tests, best, bestT, dead)) return false;
    }
    for (uint g = g0; !dead && best > 0.0; ++g) {
        LeafGroup grp = groupAt(pc.groups, g).v;
        if (g != first) {
            if (tests == pc.cellTests) return false;
            ++tests;
            if (boxDist2(q, grp.lo, grp.hi) <= best &&
                !scanGroup(q, grp, thr, pc.cellTests, tests, best, bestT, dead))
                return false;
        }
        if ((grp.leaves & RTHDIST_GROUP_LAST) != 0u) break;
    }
    return true;
}

void main() {
    uint qi = gl_GlobalInvocationID.x;
    if (qi >= pc.nq) return;
    vec4 qv = vec4At(pc.queries, qi).v;
    vec3 q = qv.xyz;
    ivec3 c = cellOfUnclamped(q, pc.grid);
    float s = pc.grid.cellSize;
    vec3 origin = gridOrigin(pc.grid);
    vec3 blockLo = origin + vec3(c - 1) * s;
    vec3 blockHi = origin + vec3(c + 2) * s;
    vec3 toLo = q - blockLo, toHi = blockHi - q;
    float dOut = min(min(min(toLo.x, toLo.y), toLo.z), min(min(toHi.x, toHi.y), toHi.z)) - pc.epsilon;

    uint64_t maxPacked = pc.maxPacked;
    float thr = deadThreshold(maxPacked, pc.lowerBound2);
    uint64_t targets = pc.targets;
    uint64_t dense = pc.dense;
    int cpa = int(pc.grid.cellsPerAxis);
    const float kInf = uintBitsToFloat(0x7f800000u);
    float best = kInf;
    uint bestT = 0;
    bool dead = false;
    bool complete = true;  // every point of the block was scanned
    for (int j = 0; j < 27 && !dead && best > 0.0; ++j) {
        // j = 0 is the query's own cell, then the 26 neighbours.
        int m = j == 0 ? 13 : (j <= 13 ? j - 1 : j);
        ivec3 cc = c + ivec3(m % 3, (m / 3) % 3, m / 9) - 1;
        if (any(lessThan(cc, ivec3(0))) || any(greaterThanEqual(cc, ivec3(cpa)))) continue;
        if (pc.mutant != 0u && j == 0) continue;  // tests only: a search that misses candidates
        if (j > 0 && best < kInf) {  // a neighbour farther than the best holds no nearer point
            vec3 lo = origin + vec3(cc) * s - pc.epsilon;
            if (boxDist2(q, lo, lo + (s + 2.0 * pc.epsilon)) > best) continue;
        }
        uint key = mortonKey(uvec3(cc));
        uint end = uintAt(dense, key).v;
        uint start = key == 0 ? 0u : uintAt(dense, key - 1).v;
        if (end - start > pc.scanMax && pc.groupFirst != 0ul) {
            // A crowded cell of a split index: its leaf groups near q.
            if (!scanCrowdedCell(q, key, start, thr, best, bestT, dead)) complete = false;
            if (!dead && j == 0) thr = deadThreshold(maxPacked, pc.lowerBound2);
            continue;
        }
        if (end - start > pc.scanMax) {
            // A crowded cell without leaves (copies of one point, or a
            // bounded pass): its first point still bounds the query, the
            // rest is left to the search.
            complete = false;
            end = start + 1u;
        }
        for (uint t = start; t < end; ++t) {
            vec4 tv = vec4At(targets, t).v;
            float d2 = dist2(q, tv.xyz);
            uint t_ = floatBitsToUint(tv.w);
            // Ties go to the smallest target index, as in the CPU backend.
            if (d2 < best || (d2 == best && t_ < bestT)) {
                best = d2;
                bestT = t_;
            }
        }
        if (best < thr) dead = true;
        else if (j == 0) thr = deadThreshold(maxPacked, pc.lowerBound2);
    }
    // Coarse levels: a coarse cell (edge s * 2^j) is a contiguous run of the
    // Morton-sorted targets, found in O(1) from the fine table. Its first
    // point is a real member: one strictly closer than the threshold proves
    // the query cannot raise h, with no ray cast. Levels stop once a coarse
    // cell's reach exceeds the threshold radius (reps there rarely help).
    bool settled = best == 0.0 || (complete && dOut > 0.0 && best <= dOut * dOut);
    if (!dead && !settled) {
        thr = deadThreshold(maxPacked, pc.lowerBound2);
        float reach = sqrt(thr);
        for (uint j = 1; j < pc.grid.bits && !dead; ++j) {
            float coarse = s * float(1u << j);
            if (coarse > reach) break;
            ivec3 cc0 = c >> int(j);
            int cpaj = cpa >> int(j);
            for (int m = 0; m < 27; ++m) {
                ivec3 cc = cc0 + ivec3(m % 3, (m / 3) % 3, m / 9) - 1;
                if (any(lessThan(cc, ivec3(0))) || any(greaterThanEqual(cc, ivec3(cpaj)))) continue;
                uint firstKey = mortonKey(uvec3(cc)) << (3u * j);
                uint lastKey = firstKey + (1u << (3u * j)) - 1u;
                uint start = firstKey == 0 ? 0u : uintAt(dense, firstKey - 1).v;
                if (uintAt(dense, lastKey).v == start) continue;  // empty coarse cell
                vec4 tv = vec4At(targets, start).v;
                float d2 = dist2(q, tv.xyz);
                uint t_ = floatBitsToUint(tv.w);
                if (d2 < best || (d2 == best && t_ < bestT)) {
                    best = d2;
                    bestT = t_;
                }
                if (best < thr) {
                    dead = true;
                    break;
                }
            }
        }
    }
    QueryState st;
    st.best = packDistIndex(best, bestT);
    st.rLo = pc.blockRLo != 0u ? max(dOut, 0.0) : 0.0;
    if (dead) {
        st.status = RTHDIST_DEAD;
    } else if (best == 0.0 || (complete && dOut > 0.0 && best <= dOut * dOut)) {
        st.status = RTHDIST_EXACT;
        raiseMax(maxPacked, packDistIndex(best, qi));
    } else {
        st.status = RTHDIST_OPEN;
    }
    stateAt(pc.state, qi).v = st;
}
