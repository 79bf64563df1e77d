// DeepMind surface-distance's surfel areas (docs/masks.md, the DeepMind
// row), derived here from the geometry. Internal to rthdist_masks.
//
// A surfel sits at a corner of the voxel grid; its 2x2x2 neighbourhood is the
// voxels (i-1+a, j-1+b, k-1+c), a, b, c in {0, 1} (a along axis 0), and its
// neighbour code has bit 128 >> (4a + 2b + c) set when that voxel is selected
// (DeepMind's kernel [[[128, 64], [32, 16]], [[8, 4], [2, 1]]], correlated
// with SciPy). Codes 0 and 255 are not surfels.
//
// The surface piece of a code is marching cubes' on the dual cube whose
// corners are those eight voxel centres, at level 1/2 (vertices at the
// midpoints of the edges joining a selected and an unselected corner):
//   - the corners taken are the minority side: the selected ones, or the
//     unselected ones when more than four are selected (so a code and its
//     complement have the same piece — marching cubes' classic table, which
//     never joins two corners that only touch diagonally);
//   - each edge-connected group of those corners is cut off by one polygon
//     through the midpoints of its outgoing edges, in the order the cube's
//     faces join them (3 to 6 vertices);
//   - a polygon is split into triangles the way of largest total area on the
//     unit cube. Only two kinds are not planar: the 5-gon around three
//     corners of a face, which then folds along the chord joining the
//     midpoints of the edges leaving the face at its two end corners, and
//     the 6-gon around a path of four corners in three directions; the
//     triangulations of equal largest area differ only inside planar parts,
//     so they agree at every spacing.
// This reproduces the table DeepMind ships (lookup_tables.py, built from a
// marching-cubes table) for all 256 codes at several spacings, bit for bit at
// unit spacing and within 1e-15 otherwise (a planar part split into other
// triangles) — checked when this was written, not in the tests, which hold no
// copy of that table.
// A triangle's area at spacing s is |(n.x s.y s.z, n.y s.x s.z, n.z s.x s.y)|
// for its area vector n on the unit cube; a code's area is the sum over its
// triangles (DeepMind's create_table_neighbour_code_to_surface_area, which
// stores those area vectors as "normals").
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace rthdist::masks::detail {

// The neighbour-code bit of the voxel at offset (a, b, c) in {0, 1}^3.
[[nodiscard]] constexpr uint8_t neighbourBit(int a, int b, int c) {
    return uint8_t(128 >> (4 * a + 2 * b + c));
}

// Area vectors (half the cross product, on the unit cube, coordinates along
// axes 0, 1, 2) of the triangles of a code's surface piece; none for 0 and 255.
[[nodiscard]] const std::vector<glm::dvec3>& surfelAreaVectors(uint8_t code);

// The area of every code's surface piece at voxel spacing `spacing` (mm²).
[[nodiscard]] std::array<double, 256> surfelAreaTable(glm::dvec3 spacing);

}  // namespace rthdist::masks::detail
