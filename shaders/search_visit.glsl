// The exact per-candidate test shared by the ray-query and the ray-tracing
// pipeline searches, so the two paths cannot diverge. Expects `pc` to be a
// SearchPush. Returns true when the query is dead (stop its traversal).
//
// Invariant (design.md §3): every cell whose tight box lies within `radius` of q
// is reported by the traversal (boxes are grown by radius + epsilon); cells
// within rLo were scanned in the previous iteration and are skipped when it
// used the same cells (skipScanned); the others
// become (query, cell) pairs for the exact refinement, unless the cell's
// representative (a real member point) is already closer than the running
// maximum, which proves the query cannot raise h. A cell whose box is farther
// than the query's best distance so far (bestLocal: scanned points and
// representatives seen) cannot hold its nearest neighbour and is skipped;
// representatives lower the query's best at once (atomicMin), so a
// one-point cell needs no pair, and neither does any cell once the query's
// best is 0 (a copy of the query: nothing can be closer).
bool visitCell(uint slot, uint qi, vec3 q, float rLo, float thr, uint cellIndex, inout float bestLocal) {
    if (bestLocal == 0.0) return false;  // a copy of q was found: nothing is closer
    Cell c = cellAt(pc.cells, cellIndex).v;
    float d2 = boxDist2(q, c.lo, c.hi);
    if (d2 > pc.radius * pc.radius) return false;
    // rLo = 0: nothing of this level was scanned yet (a query that lost pairs
    // at its first radius, or at the first radius of a new level): even the
    // cells q lies in (d2 = 0) must be visited.
    if (pc.skipScanned != 0u && rLo > 0.0 && d2 <= rLo * rLo) return false;
    if (d2 > bestLocal) return false;
    vec4 rep = vec4At(pc.targets, c.first).v;
    float r2 = dist2(q, rep.xyz);
    if (r2 < thr) {
        // The killing point becomes the query's best: the self-check then
        // sees every dead query below the final maximum.
        atomicMin(stateAt(pc.state, qi).v.best, packDistIndex(r2, floatBitsToUint(rep.w)));
        stateAt(pc.state, qi).v.status = RTHDIST_DEAD;
        return true;
    }
    if (r2 < bestLocal) {
        bestLocal = r2;
        atomicMin(stateAt(pc.state, qi).v.best, packDistIndex(r2, floatBitsToUint(rep.w)));
    }
    // One point, copies of one point (the representative stands for all), or
    // a copy of q: the representative was all the cell could offer.
    if (c.count == 1 || r2 == 0.0 || all(equal(c.lo, c.hi))) return false;
    uint64_t idx = atomicAdd(U64Ref(pc.counters + RTHDIST_CTR_PAIRS).v, 1ul);
    if (idx < uint64_t(pc.pairCapacity)) {
        uvec2At(pc.pairs, uint(idx)).v = uvec2(slot, cellIndex);
    } else {
        stateAt(pc.state, qi).v.status = RTHDIST_RETRY;
    }
    return false;
}

// RadiusSchedule's retry classes: while a full pair buffer stalls the search,
// one class of queries (qi % retryStride == retryPhase) is searched at a time
// and the others wait, marked RETRY (resolve.comp keeps them open with the
// rLo they had, or 0 after a level change: nothing is skipped on their word).
// Returns true when q waits this radius out.
bool waitsForItsClass(uint qi) {
    if (pc.retryStride <= 1u || qi % pc.retryStride == pc.retryPhase) return false;
    stateAt(pc.state, qi).v.status = RTHDIST_RETRY;
    return true;
}
