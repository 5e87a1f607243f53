// seeds/001 ("badanie przecięcia promień-sfera", R. Kraus): unit direction, A = 1;
// the nearer root beyond epsilon5, else the farther one (so rays from inside hit).
#pragma once
#include <cmath>
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::sphere_kraus {

// The document's epsilon5: roots at or nearer than 1e-5 (a distance, since
// the direction is unit) are dropped, against self-intersection.
inline constexpr double epsilon5 = 1e-5;

template <class T>
std::optional<SurfaceHit<T>> hit(const Ray<T>& r, const Vec3<T>& center, T radius) {
  // The listing needs |aheadDir| = 1 ("a dbamy o to"); our rays need not be,
  // so normalise here and map t back: t_caller = t_unit / |d|.
  const T dd = dot(r.d, r.d);
  const T len = dd == T(1) ? T(1) : std::sqrt(dd);
  const Vec3<T> dir = dd == T(1) ? r.d : r.d / len;
  const Vec3<T> v = r.o - center;
  const T b = dot(v, dir);
  const T d2 = b * b - dot(v, v) + radius * radius;
  if (!(d2 >= T(0))) return std::nullopt;  // also NaN, from a zero direction
  const T d = std::sqrt(d2);
  const T t1 = -b - d, t2 = -b + d;
  // The listing returns t1 if > epsilon5, else t2 if > epsilon5; the window
  // is applied to each candidate too, in the caller's parametrisation.
  if (t1 > T(epsilon5) && t1 / len >= r.tmin && t1 / len <= r.tmax) return SurfaceHit<T>{t1 / len};
  if (t2 > T(epsilon5) && t2 / len >= r.tmin && t2 / len <= r.tmax) return SurfaceHit<T>{t2 / len};
  return std::nullopt;
}

}  // namespace ra::sphere_kraus
