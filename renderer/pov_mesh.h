// POV-Ray 3.7's own mesh2 arithmetic (source/backend/shape/mesh.cpp and the
// parser's Parse_Mesh2, v3.7.0.10), for validation/pov_explain's hypotheses:
// where POV puts the hit point of a ray on a triangle and at which
// barycentrics it interpolates the triangle's smooth normals there.
//
// POV keeps, per triangle of a mesh2, everything in float32: the vertices,
// the normals (normalised, then rounded), the unit plane normal
// S = (C - A) x (B - A) and the plane's distance D = -S.A (computed in double
// from the float vertices, then rounded). A ray meets the plane at
//   t = -(D + S.O) / (S.Dir)           (double, with the float S and D)
// and the hit point is O + t Dir: not on the plane of the float vertices but
// off it by D's and S's rounding, ~1e-7 at unit scale, i.e. ~1e-7 / |cos| along
// the ray. The smooth normal is interpolated at that point through the float
// vector `Perp` of compute_smooth_triangle (after the vertex swap of
// Compute_Mesh_Triangle): u = (P - P1).Perp, and below 1e-10 the normal is
// N1's alone. Perp is a float vector whose every step (the difference, its
// normalisation, the division by -uDenominator) is done in float by the
// SNGL_VECT overloads of math/vector.h; the UVs (UV_VECT) are double.
//
// Where the smooth normals vary fast (small triangles on a curved surface),
// that moves N.L by 1e-6 to 1e-4, enough to cross an 8-bit rounding boundary:
// measured on corpus/ladder-100k-bunny (scenes/corpus/pov/).
#pragma once
#include <array>
#include <optional>

#include "ray.h"
#include "vec.h"

namespace ra {

struct PovMeshHit {
  Vec3d p;                // O + t Dir, t from POV's float32 plane
  double b1 = 0, b2 = 0;  // POV's weights of b and c at p (a has 1 - b1 - b2)
  bool ok = false;        // false: the ray is parallel to the plane (|S.Dir| < 1e-10)
};

// The hit of ray r on triangle (a, b, c), listed in that order in the mesh2's
// face_indices, as POV-Ray computes it. The vertices are rounded to float32
// here (as POV stores them). The triangle must not be degenerate.
PovMeshHit pov_mesh_hit(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c);

// Does the ray meet triangle (a, b, c) by POV-Ray's own mesh2 test
// (intersect_mesh_triangle of mesh.cpp), and at which t? The depth comes from
// the float32 plane (as above), must lie in [1e-6, 1e7] (its DEPTH_TOLERANCE
// and MAX_DISTANCE), and the point O + t Dir is kept when it lies inside the
// triangle projected along the plane normal's dominant axis: three 2D edge
// tests on the float32 vertices (after the vertex swap), each `<` rejecting,
// so a point on an edge is inside. Unlike an edge test on the vertices in 3D,
// this point is off the vertices' plane by the float32 plane's rounding, and
// near an edge the two answers can differ. The ray's own window is not
// applied (callers do). nullopt: a miss, or a degenerate triangle.
// The texture coordinates POV-Ray gives point p of triangle (a, b, c) with
// UVs (ua, ub, uc): Mesh::UVCoord, which weighs each vertex by projecting
// P - vertex onto the perpendicular of the opposite side, the sides taken as
// float32 differences of the float32 vertices (after the vertex swap):
// the barycentric weights in exact arithmetic, but rounded differently from
// the Perp interpolation used for normals and from ours.
std::array<double, 2> pov_mesh_uv(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                                  const std::array<double, 2>& ua, const std::array<double, 2>& ub,
                                  const std::array<double, 2>& uc);

// The normal POV-Ray shades a flat mesh2 triangle with: computed in
// Compute_Mesh_Triangle as (C - A) x (B - A) of the float32 vertices, times
// 1/length, and stored as float32 (Mesh_Hash_Normal); Mesh::Normal returns
// it as it is. Zero for a degenerate triangle.
Vec3d pov_mesh_flat_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c);

std::optional<double> pov_mesh_intersect(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace ra
