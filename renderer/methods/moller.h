// Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 2(1), 1997. No stored plane; not watertight (edges shared by two
// triangles can leak or double-hit because each evaluates its own edge terms).
#pragma once
#include <cmath>
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::moller {

// The determinant threshold of the paper's EPSILON: exactly 0 here, so that
// only truly parallel rays are rejected; a tolerance would be a silent bias.
template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  const Vec3<T> e1 = b - a, e2 = c - a;
  const Vec3<T> p = cross(r.d, e2);
  const T det = dot(e1, p);
  // det > 0 when the ray meets the front face (normal e1 x e2 against d).
  if (cull ? !(det > T(0)) : !(det != T(0))) return std::nullopt;
  const T inv = T(1) / det;
  const Vec3<T> s = r.o - a;
  const T u = dot(s, p) * inv;
  if (!(u >= T(0) && u <= T(1))) return std::nullopt;
  const Vec3<T> q = cross(s, e1);
  const T v = dot(r.d, q) * inv;
  if (!(v >= T(0) && u + v <= T(1))) return std::nullopt;
  const T t = dot(e2, q) * inv;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  return TriangleHit<T>{t, u, v};
}

}  // namespace ra::moller
