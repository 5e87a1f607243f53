#include "pov_mesh.h"

#include <cmath>
#include <utility>

namespace ra {
namespace {

// POV-Ray's EPSILON (frame.h).
constexpr double kPovEpsilon = 1e-10;

// max3_coordinate of mesh.cpp: ties go to the later axis.
int max3_coordinate(double x, double y, double z) { return x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2); }

}  // namespace

PovMeshHit pov_mesh_hit(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  PovMeshHit out;
  // Compute_Mesh_Triangle: the plane, from the float vertices in double, then
  // stored as float32.
  Vec3d p1 = to_float32(a), p2 = to_float32(b), p3 = to_float32(c);
  Vec3d s = cross(p3 - p1, p2 - p1);
  s = s / length(s);
  const double distance = to_float32(-dot(s, p1));
  const Vec3d sf = to_float32(s);
  // intersect_mesh_triangle and test_hit: t from the stored plane, the point
  // on the ray.
  const double nd = dot(sf, r.d);
  if (std::fabs(nd) < kPovEpsilon) return out;
  const double t = -(distance + dot(sf, r.o)) / nd;
  out.p = r.o + r.d * t;
  out.ok = true;

  // The vertex swap of Compute_Mesh_Triangle (P1 and P2 trade places, with
  // their normals), decided on the dominant axis of the plane normal.
  const int dom = max3_coordinate(std::fabs(s.x), std::fabs(s.y), std::fabs(s.z));
  const int i = dom == 0 ? 1 : 0, j = dom == 2 ? 1 : 2;
  const bool swap = (p2[i] - p3[i]) * (p2[j] - p1[j]) < (p2[j] - p3[j]) * (p2[i] - p1[i]);
  if (swap) std::swap(p1, p2);

  // compute_smooth_triangle: Perp, float32, scaled so that (P - P1).Perp
  // runs from 0 at P1 to 1 on the edge P2 P3.
  const Vec3d p3p2 = p3 - p2;
  const int axis = max3_coordinate(std::fabs(p3p2.x), std::fabs(p3p2.y), std::fabs(p3p2.z));
  Vec3d t1 = normalize(p2 - p3);
  const Vec3d t2 = p1 - p3;
  t1 = t1 * dot(t2, t1);
  Vec3d perp = to_float32(normalize(t1 - t2));
  const double u_denominator = -dot(t2, perp);
  perp = to_float32(perp / u_denominator);

  // Smooth_Mesh_Normal: N = N1 + u (N2 - N1 + v (N3 - N2)), i.e. weights
  // 1 - u, u (1 - v), u v of P1, P2, P3.
  const Vec3d pi_p1 = out.p - p1;
  const double u = dot(pi_p1, perp);
  double w1 = 0, w2 = 0, w3 = 0;  // of P1, P2, P3 (after the swap)
  if (u < kPovEpsilon) {
    w1 = 1;
  } else {
    const double v = (pi_p1[axis] / u + p1[axis] - p2[axis]) / (p3[axis] - p2[axis]);
    w1 = 1 - u;
    w2 = u * (1 - v);
    w3 = u * v;
  }
  // Back to our a, b, c: P3 is c; P1, P2 are a, b (or b, a when swapped).
  out.b1 = swap ? w1 : w2;
  out.b2 = w3;
  return out;
}

}  // namespace ra
