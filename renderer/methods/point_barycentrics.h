// Shared by the document methods that decide inside/outside without computing
// barycentrics (angles, areas, sameside): (b1, b2) of a point, after the fact.
#pragma once
#include "../hit.h"
#include "../ray.h"

namespace ra::detail {

// Signed barycentrics of P projected onto the plane of ABC, in hit.h's
// convention P = (1 - b1 - b2) A + b1 B + b2 C. Signed so that a point a
// document's tolerance accepted outside the triangle reports a slightly
// negative coordinate rather than a misleading positive one.
template <class T>
TriangleHit<T> hit_from_point(T t, const Vec3<T>& p, const Vec3<T>& a, const Vec3<T>& b,
                              const Vec3<T>& c) {
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

}  // namespace ra::detail
