// Baldwin & Weber, "Fast Ray-Triangle Intersections by Coordinate Transformation",
// JCGT 5(3), 2016: a stored affine map to barycentric space; not watertight; edges inclusive.
#pragma once
#include <cmath>
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::baldwin {

// The per-triangle precomputation: three rows of a 3x4 affine map taking
// world points to (b1, b2, w), w = 0 on the triangle's plane. We store all 12
// values (the paper's first option) rather than 9 + the fixed column's index,
// so the test has no branch: 48 bytes in float, 96 in double.
template <class T>
struct Transform {
  T m[12];
};
static_assert(sizeof(Transform<float>) == 48 && sizeof(Transform<double>) == 96);

// Builds the map. k is the axis of the largest |n| (n = (B-A) x (C-A)); each
// row has 0, 0, and +-1 in column k, so only n[k] is divided by (the paper's
// choice of the free column). One change from the paper: the w row is n / |n[k]|
// rather than n / n[k], so the sign of w's direction term is the sign of n.d
// and culling needs no stored sign; t = -w(o) / w(d) is unchanged.
template <class T>
Transform<T> prepare(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  const Vec3<T> e1 = b - a, e2 = c - a, n = cross(e1, e2);
  const int k = max_dimension(abs(n));
  const int i = k + 1 == 3 ? 0 : k + 1;
  const int j = i + 1 == 3 ? 0 : i + 1;
  const T inv = T(1) / n[k];  // n[k] = e1[i] e2[j] - e1[j] e2[i]
  Vec3<T> u, v;               // u.e1 = 1, u.e2 = 0; v.e1 = 0, v.e2 = 1; both 0 in column k
  u[i] = e2[j] * inv;
  u[j] = -e2[i] * inv;
  v[i] = -e1[j] * inv;
  v[j] = e1[i] * inv;
  const Vec3<T> w = n * std::abs(inv);
  return {{u.x, u.y, u.z, -dot(u, a), v.x, v.y, v.z, -dot(v, a), w.x, w.y, w.z, -dot(w, a)}};
}

template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Transform<T>& tr, bool cull) {
  const T* m = tr.m;
  const T w_o = m[8] * r.o.x + m[9] * r.o.y + m[10] * r.o.z + m[11];
  const T w_d = m[8] * r.d.x + m[9] * r.d.y + m[10] * r.d.z;
  // w_d has the sign of n.d: < 0 for a front face; 0 for a parallel ray.
  if (cull ? !(w_d < T(0)) : !(w_d != T(0))) return std::nullopt;
  const T t = -w_o / w_d;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  const Vec3<T> p = r.at(t);
  const T b1 = m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3];
  if (!(b1 >= T(0) && b1 <= T(1))) return std::nullopt;
  const T b2 = m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7];
  if (!(b2 >= T(0) && b1 + b2 <= T(1))) return std::nullopt;
  return TriangleHit<T>{t, b1, b2};
}

template <class T>
bool any(const Ray<T>& r, const Transform<T>& tr, bool cull) {
  return hit(r, tr, cull).has_value();
}

// The direct path: builds the map for this one call, then runs the test (for
// the audit; meshes and benchmarks prepare once per triangle).
template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return hit(r, prepare(a, b, c), cull);
}

template <class T>
bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return hit(r, prepare(a, b, c), cull).has_value();
}

}  // namespace ra::baldwin
