#include "pov_mesh.h"

#include <cmath>
#include <utility>

namespace ra {
namespace {

// POV-Ray's EPSILON (frame.h).
constexpr double kPovEpsilon = 1e-10;
// mesh.cpp's DEPTH_TOLERANCE, and MAX_DISTANCE (frame.h).
constexpr double kPovMeshDepthTolerance = 1e-6;
constexpr double kPovMaxDistance = 1e7;

// max3_coordinate of mesh.cpp: ties go to the later axis.
int max3_coordinate(double x, double y, double z) { return x > y ? (x > z ? 0 : 2) : (y > z ? 1 : 2); }

// Compute_Mesh_Triangle's unit plane normal: (P3 - P1) x (P2 - P1) times
// 1 / |.| (VInverseScaleEq multiplies by the reciprocal), in double from the
// float32 vertices.
Vec3d unit_plane_normal(const Vec3d& p1, const Vec3d& p2, const Vec3d& p3) {
  const Vec3d s = cross(p3 - p1, p2 - p1);
  const double len = std::sqrt(s.x * s.x + s.y * s.y + s.z * s.z);
  if (len == 0) return {0, 0, 0};
  const double inv = 1.0 / len;
  return {s.x * inv, s.y * inv, s.z * inv};
}

// Compute_Mesh_Triangle's vertex swap of P1 and P2, decided on the float32
// vertices and the dominant axis of the plane normal, so that the 2D edge
// tests of intersect_mesh_triangle all face the same way.
bool swapped(const Vec3d& p1, const Vec3d& p2, const Vec3d& p3) {
  const Vec3d s = unit_plane_normal(p1, p2, p3);  // POV takes the axis of the unit normal
  const int dom = max3_coordinate(std::fabs(s.x), std::fabs(s.y), std::fabs(s.z));
  const int i = dom == 0 ? 1 : 0, j = dom == 2 ? 1 : 2;
  return (p2[i] - p3[i]) * (p2[j] - p1[j]) < (p2[j] - p3[j]) * (p2[i] - p1[i]);
}

// compute_smooth_triangle's Perp, in POV-Ray's own precisions
// (math/vector.h overloads): VTemp1 = unit(P2 - P3) scaled by
// (P1 - P3).VTemp1 is double; but Perp is a float vector (SNGL_VECT), so
// VSub(Perp, VTemp1, VTemp2) rounds the difference to float, VNormalize of a
// float vector takes its length and 1 / length in float, and
// VInverseScaleEq(Perp, -uDenominator) converts the double uDenominator to
// float, rounds 1.0 / k to float and multiplies in float. Modelling Perp as
// a rounded double computation instead put smooth normals ~1e-7 off POV's,
// which two reflections on a small smooth mesh with fast-varying UVs
// amplify to another texel (random scene 3-179, pixel (87, 95)).
Vec3d pov_perp(const Vec3d& p1, const Vec3d& p2, const Vec3d& p3) {
  // A float operation done in double and then rounded gives float's own
  // result (double holds more than twice float's digits); to_float32, as
  // GCC may drop a plain conversion (vec.h).
  auto f = [](double x) { return to_float32(x); };
  Vec3d t1 = p2 - p3;
  const double inv1 = 1.0 / std::sqrt(t1.x * t1.x + t1.y * t1.y + t1.z * t1.z);
  t1 = {t1.x * inv1, t1.y * inv1, t1.z * inv1};
  const Vec3d t2 = p1 - p3;
  const double proj = t2.x * t1.x + t2.y * t1.y + t2.z * t1.z;
  t1 = {t1.x * proj, t1.y * proj, t1.z * proj};
  Vec3d q{f(t1.x - t2.x), f(t1.y - t2.y), f(t1.z - t2.z)};
  const double inv = f(1.0 / f(std::sqrt(f(f(f(q.x * q.x) + f(q.y * q.y)) + f(q.z * q.z)))));
  q = {f(q.x * inv), f(q.y * inv), f(q.z * inv)};
  const double u_denominator = t2.x * q.x + t2.y * q.y + t2.z * q.z;
  const double invk = f(1.0 / f(-u_denominator));
  return {f(q.x * invk), f(q.y * invk), f(q.z * invk)};
}

}  // namespace

Vec3d pov_mesh_flat_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d p1 = to_float32(a), p2 = to_float32(b), p3 = to_float32(c);
  const Vec3d v1 = p2 - p1, v2 = p3 - p1;
  Vec3d n = cross(v2, v1);
  const double len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  if (!(len > 0)) return {0, 0, 0};
  n = n * (1.0 / len);
  return to_float32(n);
}

PovMeshHit pov_mesh_hit(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  PovMeshHit out;
  // Compute_Mesh_Triangle: the plane, from the float vertices in double, then
  // stored as float32.
  Vec3d p1 = to_float32(a), p2 = to_float32(b), p3 = to_float32(c);
  const Vec3d s = unit_plane_normal(p1, p2, p3);
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
  // runs from 0 at P1 to 1 on the edge P2 P3 (pov_perp).
  const Vec3d p3p2 = p3 - p2;
  const int axis = max3_coordinate(std::fabs(p3p2.x), std::fabs(p3p2.y), std::fabs(p3p2.z));
  const Vec3d perp = pov_perp(p1, p2, p3);

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

std::array<double, 2> pov_mesh_uv(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                                  const std::array<double, 2>& ua, const std::array<double, 2>& ub,
                                  const std::array<double, 2>& uc) {
  Vec3d p1 = to_float32(a), p2 = to_float32(b), p3 = to_float32(c);
  // UVs stay double: POV's UV_VECT is DBL[2] (frame.h), parsed from the
  // mesh2's text (only vertices and normals are SNGL_VECT).
  std::array<double, 2> uv1 = ua, uv2 = ub, uv3 = uc;
  if (swapped(p1, p2, p3)) {
    std::swap(p1, p2);
    std::swap(uv1, uv2);
  }
  // Data->Vertices[i] - Data->Vertices[j] is a float32 subtraction.
  auto fsub = [](const Vec3d& x, const Vec3d& y) { return to_float32(x - y); };
  // The weight of vertex pa, whose opposite side runs pb -> pc.
  auto weight = [&](const Vec3d& pa, const Vec3d& pb, const Vec3d& pc) {
    const Vec3d side1 = fsub(pc, pb), side2 = fsub(pc, pa);
    const Vec3d va = p - pa;
    const double k = dot(side2, side1) / dot(side1, side1);
    const Vec3d vb = side1 * k - side2;
    return 1 + dot(va, vb) / dot(vb, vb);
  };
  const double w1 = weight(p1, p2, p3), w2 = weight(p2, p1, p3), w3 = weight(p3, p1, p2);
  return {w1 * uv1[0] + w2 * uv2[0] + w3 * uv3[0], w1 * uv1[1] + w2 * uv2[1] + w3 * uv3[1]};
}

std::optional<double> pov_mesh_intersect(const Ray<double>& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  // Compute_Mesh_Triangle, as in pov_mesh_hit.
  Vec3d p1 = to_float32(a), p2 = to_float32(b), p3 = to_float32(c);
  const Vec3d s = unit_plane_normal(p1, p2, p3);
  if (s == Vec3d{0, 0, 0}) return std::nullopt;  // POV drops degenerate triangles
  const double distance = to_float32(-dot(s, p1));
  const Vec3d sf = to_float32(s);
  const int dom = max3_coordinate(std::fabs(s.x), std::fabs(s.y), std::fabs(s.z));
  const int i = dom == 0 ? 1 : 0, j = dom == 2 ? 1 : 2;
  if ((p2[i] - p3[i]) * (p2[j] - p1[j]) < (p2[j] - p3[j]) * (p2[i] - p1[i])) std::swap(p1, p2);

  // intersect_mesh_triangle.
  const double nd = dot(sf, r.d);
  if (std::fabs(nd) < kPovEpsilon) return std::nullopt;
  const double t = -(distance + dot(sf, r.o)) / nd;
  if (t < kPovMeshDepthTolerance || t > kPovMaxDistance) return std::nullopt;
  const double u = r.o[i] + t * r.d[i], v = r.o[j] + t * r.d[j];
  if ((p2[i] - u) * (p2[j] - p1[j]) < (p2[j] - v) * (p2[i] - p1[i])) return std::nullopt;
  if ((p3[i] - u) * (p3[j] - p2[j]) < (p3[j] - v) * (p3[i] - p2[i])) return std::nullopt;
  if ((p1[i] - u) * (p1[j] - p3[j]) < (p1[j] - v) * (p1[i] - p3[i])) return std::nullopt;
  return t;
}

}  // namespace ra
