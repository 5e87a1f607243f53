// Haines, Günther, Akenine-Möller, "Precision Improvements for Ray/Sphere
// Intersection", Ray Tracing Gems ch. 7 (2019): the discriminant from geometry
// (r^2 - |f - (f.d^) d^|^2, accurate for small spheres far away) and the roots
// from q = -(b + sign(b) sqrt(disc)) / 2, which avoids cancellation in -b + sqrt.
#pragma once
#include <cmath>
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::sphere_stable {

// Returns the nearest root inside [tmin, tmax]; a ray starting inside the
// sphere gets the far root.
template <class T>
std::optional<SurfaceHit<T>> hit(const Ray<T>& r, const Vec3<T>& center, T radius) {
  const Vec3<T> f = r.o - center;
  const T a = dot(r.d, r.d);
  const T b = -dot(f, r.d);                    // b' = -(f.d): half of -B
  const Vec3<T> l = f + r.d * (b / a);         // f minus its projection on d
  const T disc = radius * radius - dot(l, l);  // (per unit a) discriminant / 4
  if (!(disc >= T(0))) return std::nullopt;
  const T s = std::sqrt(a * disc);
  // q = b' + sign(b') sqrt(a disc); roots are c/q and q/a (RTG eq. 7.13).
  const T q = b + std::copysign(s, b);
  const T c = dot(f, f) - radius * radius;
  T t0 = (q != T(0)) ? c / q : T(0);
  T t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 >= r.tmin && t0 <= r.tmax) return SurfaceHit<T>{t0};
  if (t1 >= r.tmin && t1 <= r.tmax) return SurfaceHit<T>{t1};
  return std::nullopt;
}

}  // namespace ra::sphere_stable
