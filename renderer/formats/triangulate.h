// Ear clipping of one planar polygon (Meisters 1975, "Polygons have ears")
// on a linked ring, testing only the corners that are not convex, found
// through a uniform grid: O(n) for a convex polygon, about O(n) for small
// ears, and never more than kEarClipWorkPerCorner steps a corner (below).
// The polygon is projected onto the coordinate plane most perpendicular to its Newell normal, in
// coordinates relative to its first vertex so that large offsets do not eat
// the precision (tinyobjloader #295 lost faces that way).
// Guarantee: always n-2 triangles, each (a, b, c) listed in the polygon's
// own winding; for a simple polygon (convex or concave) they tile it exactly.
// For a degenerate or self-intersecting one, when no ear is left the first
// remaining corner is cut anyway (a fan), so the count still holds.
// A convex polygon comes out as the fan (0,1,2), (0,2,3), ...
// Work limit: a polygon whose ear search would take more than
// kEarClipWorkPerCorner point tests a corner (a spiky polygon of hundreds of
// thousands of corners, quadratic otherwise: 44 s for 200k corners; 500, not
// 200, so that a star of 5,000 corners with its inner ones clustered at 1%
// of its radius still tiles exactly; a face of a million corners then takes
// 1.4 s instead of 0.75) has its
// remaining corners cut in order, like a degenerate one. So any file
// triangulates in time linear in its size. Those triangles may
// overlap or leave gaps: triangulate_polygon returns true then, and the OBJ
// reader warns "FILE:LINE: polygon of N corners ..." (the file still loads:
// the mesh is what the file says up to that polygon's tiling).
#pragma once
#include <array>
#include <vector>

#include "../vec.h"

namespace ra {

inline constexpr long kEarClipWorkPerCorner = 500;

// Readers refuse a polygon of more corners (FILE:LINE): its triangulation
// holds about 130 bytes a corner (a 20 MB face of 9M corners needed 1.2 GB
// and 200 steps a corner). No real mesh comes near it.
inline constexpr int kMaxPolygonCorners = 1000000;  // as PLY and OFF face sizes

struct EarClipScratch {
  std::vector<int> next, prev, reflex, cell_start, cell_items;
  std::vector<char> alive;
  std::vector<std::array<double, 2>> q;
};

// Appends the triangles of polygon pts[0..n) as index triples into `out`.
// Returns true when the work limit was spent (the rest cut as a fan).
bool triangulate_polygon(const Vec3d* pts, int n, std::vector<std::array<int, 3>>& out, EarClipScratch& scratch);

}  // namespace ra
