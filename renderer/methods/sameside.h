// seeds/004 (CodeProject C#, tTriangle.GetInterSect / PointInTriangle): plane
// hit, parallel when |N.v| < 1e-6, then "same side" per edge with >= 0; two-sided, edges inclusive.
#pragma once
#include <cmath>
#include <optional>

#include "point_barycentrics.h"

namespace ra::sameside {

// The listing's parallel threshold on N.v, where neither N (getNormal, an
// unnormalised cross product) nor v (the eye-to-screen segment) is unit: the
// test is scale dependent, so small triangles or short directions are
// rejected as "parallel" even head-on. Kept as written.
inline constexpr double kParallel = 1.0E-6;

// The listing's SameSide(p1, p2, a, b): are p1 and p2 on the same side of the
// line ab? Zero (a point on the line) counts as the same side.
template <class T>
bool same_side(const Vec3<T>& p1, const Vec3<T>& p2, const Vec3<T>& a, const Vec3<T>& b) {
  const Vec3<T> cp1 = cross(b - a, p1 - a);
  const Vec3<T> cp2 = cross(b - a, p2 - a);
  return dot(cp1, cp2) >= T(0);
}

// The hit parameter if the document accepts the hit, nothing otherwise.
// Barycentrics are not part of the method: detail::DecidesT
// (point_barycentrics.h) computes them from the hit point after this decision.
template <class T>
std::optional<T> accept(const Ray<T>& r, const Vec3<T>& A, const Vec3<T>& B, const Vec3<T>& C, bool cull) {
  // getNormal computes (C - A) x (B - A): the opposite of registry.h's front
  // normal. GetInterSect divides two dots with it, so the sign cancels; only
  // culling needs the registry's orientation, and flips it back.
  const Vec3<T> N = cross(C - A, B - A);
  if (cull && detail::culled(r, -N)) return std::nullopt;
  const T dot1 = dot(N, C - r.o);  // tp3 - p1
  const T dot2 = dot(N, r.d);      // v = p2 - p1: our direction
  if (std::abs(dot2) < T(kParallel)) return std::nullopt;
  const T u = dot1 / dot2;
  if (!detail::in_window(r, u)) return std::nullopt;
  const Vec3<T> p = r.at(u);
  // PointInTriangle: edge BC against A, edge AC against B, edge AB against C.
  if (!(same_side(p, A, B, C) && same_side(p, B, A, C) && same_side(p, C, A, B))) return std::nullopt;
  return u;
}

}  // namespace ra::sameside
