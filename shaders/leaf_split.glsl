// Shared rules of the leaf split (leaf_slots.comp, leaf_keys.comp).

// Bits per axis of a cell's split: 0 (kept whole) unless it holds more than
// leafMax points that are not all identical; then k = ceil(log8(count / 8)),
// clamped to [1, 7], so about 8 points fall in each sub-cell of even data and
// 8^k never exceeds the count.
uint splitBits(Cell c, uint leafMax) {
    if (c.count <= leafMax || all(equal(c.lo, c.hi))) return 0u;
    float k = ceil(log2(float(c.count) / 8.0) / 3.0);
    return uint(clamp(k, 1.0, 7.0));
}

// Sub-cell of p in a split cell: per axis 2^k parts of the tight box (an axis
// of zero extent has one part). Any partition is exact: the sub-cells only
// order the points, the leaves' boxes are recomputed from the points.
uint subCellKey(vec3 p, Cell c, uint k) {
    vec3 ext = c.hi - c.lo;
    float parts = float(1u << k);
    vec3 scale = vec3(ext.x > 0.0 ? parts / ext.x : 0.0, ext.y > 0.0 ? parts / ext.y : 0.0,
                      ext.z > 0.0 ? parts / ext.z : 0.0);
    uvec3 sub = uvec3(clamp(floor((p - c.lo) * scale), vec3(0.0), vec3(parts - 1.0)));
    return mortonKey(sub);
}
