// Shared by the document methods that decide inside/outside without computing
// barycentrics (angles, areas, sameside): (b1, b2) of a point, after the fact.
#pragma once
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::detail {

// Signed barycentrics of P projected onto the plane of ABC, in hit.h's
// convention P = (1 - b1 - b2) A + b1 B + b2 C. Signed so that a point a
// document's tolerance accepted outside the triangle reports a slightly
// negative coordinate rather than a misleading positive one.
template <class T>
TriangleHit<T> hit_from_point(T t, const Vec3<T>& p, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  const Vec3<T> e1 = b - a, e2 = c - a, ap = p - a;
  const Vec3<T> n = cross(e1, e2);
  const T inv = T(1) / dot(n, n);
  // ap = b1 e1 + b2 e2  =>  ap x e2 = b1 n  and  e1 x ap = b2 n.
  return {t, dot(cross(ap, e2), n) * inv, dot(cross(e1, ap), n) * inv};
}

// The ray window check every method applies on top of its own rules.
template <class T>
bool in_window(const Ray<T>& r, T t) {
  return t >= r.tmin && t <= r.tmax;
}

// The culling rule of registry.h: the front is the side (B - A) x (C - A)
// points to, so a ray meets a front face when dot(d, n) < 0.
template <class T>
bool culled(const Ray<T>& r, const Vec3<T>& n) {
  return !(dot(r.d, n) < T(0));
}

// hit() and any() of a document method that decides only t (angles, areas,
// sameside: D::accept, the document's own plane step and inside test). Their
// barycentrics are not part of the method: hit() computes them from the hit
// point after the document's inside decision; any() is that decision.
template <class D>
struct DecidesT {
  template <class T>
  static std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                           bool cull) {
    const std::optional<T> t = D::template accept<T>(r, a, b, c, cull);
    if (!t) return std::nullopt;
    return hit_from_point(*t, r.at(*t), a, b, c);
  }
  template <class T>
  static bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
    return D::template accept<T>(r, a, b, c, cull).has_value();
  }
};

}  // namespace ra::detail
