// The exact scan of a query's candidate cells, shared by refine.comp (one
// (query, search cell) pair) and tail_scan.comp (every search cell of a
// level). Include after common.glsl.
//
// Exactness (design.md §3): a cell whose box is farther than min(bound, best)
// is skipped (float rounding is monotone, so no point in it is nearer than
// its box; equal distances are kept for the tie rule); copies of one point
// (a cell whose box is one position) scan only their first; ties go to the
// smallest target index, as on the CPU backend. The scan stops once a point
// is strictly closer than thr (the query is dead: it cannot raise h) or at
// distance 0 (nothing can be closer).

// Squared distance from q to the farthest corner of the box [lo, hi]: no
// point of the box has a larger dist2, in float too (each component's
// difference is at most the larger corner difference, rounding is
// monotone, and the sum is formed as dist2 forms it), so the box holds a
// point within it.
float boxFarDist2(vec3 q, vec3 lo, vec3 hi) {
    precise vec3 d = max(abs(q - lo), abs(q - hi));
    precise float r = d.x * d.x + d.y * d.y + d.z * d.z;
    return r;
}

// The points of one level-0 cell.
void scanCellPoints(vec3 q, Cell c, uint64_t targets, float thr, inout float best, inout uint bestT,
                    inout bool dead) {
    uint end = all(equal(c.lo, c.hi)) ? c.first + 1u : c.first + c.count;
    for (uint t = c.first; t < end; ++t) {
        vec4 tv = vec4At(targets, t).v;
        float d2 = dist2(q, tv.xyz);
        uint t_ = floatBitsToUint(tv.w);
        if (d2 < best || (d2 == best && t_ < bestT)) {
            best = d2;
            bestT = t_;
            if (best < thr) {
                dead = true;
                return;
            }
            if (best == 0.0) return;
        }
    }
}

// The level-0 cells [f0, f1) of `fine`, each skipped when its box is
// farther than min(bound, best).
void scanFineCells(vec3 q, uint f0, uint f1, float bound, float thr, uint64_t fine, uint64_t targets,
                   inout float best, inout uint bestT, inout bool dead) {
    for (uint f = f0; f < f1 && !dead && best > 0.0; ++f) {
        Cell c = cellAt(fine, f).v;
        if (boxDist2(q, c.lo, c.hi) > min(bound, best)) continue;
        scanCellPoints(q, c, targets, thr, best, bestT, dead);
    }
}
