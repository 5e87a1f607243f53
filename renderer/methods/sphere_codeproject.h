// seeds/004 (CodeProject C#, "Line x Sphere Intersection"): the expanded quadratic
// on an unnormalised direction with D >= 0; as printed it keeps the FAR root (a bug).
#pragma once
#include <algorithm>
#include <cmath>
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::sphere_codeproject {

// The listing's roots t1 <= t2 from A, B, C written out in coordinates, as
// printed (C expanded term by term, which cancels badly far from the origin).
template <class T>
bool roots(const Ray<T>& r, const Vec3<T>& center, T radius, T& t1, T& t2) {
  const T px = r.o.x, py = r.o.y, pz = r.o.z;
  const T vx = r.d.x, vy = r.d.y, vz = r.d.z;
  const T cx = center.x, cy = center.y, cz = center.z;
  const T A = (vx * vx + vy * vy + vz * vz);
  const T B = T(2) * (px * vx + py * vy + pz * vz - vx * cx - vy * cy - vz * cz);
  const T C = px * px - T(2) * px * cx + cx * cx + py * py - T(2) * py * cy + cy * cy + pz * pz - T(2) * pz * cz +
              cz * cz - radius * radius;
  const T D = B * B - T(4) * A * C;
  if (!(D >= T(0))) return false;
  t1 = (-B - std::sqrt(D)) / (T(2) * A);
  t2 = (-B + std::sqrt(D)) / (T(2) * A);
  if (t1 > t2) std::swap(t1, t2);
  return true;
}

// As written: `if (t1 > t2) t = t1; else t = t2;` keeps the larger root, the
// point where the ray leaves the sphere. Wrong on purpose (registry says so).
template <class T>
std::optional<SurfaceHit<T>> hit_as_written(const Ray<T>& r, const Vec3<T>& center, T radius) {
  T t1, t2;
  if (!roots(r, center, radius, t1, t2)) return std::nullopt;
  if (!(t2 >= r.tmin && t2 <= r.tmax)) return std::nullopt;
  return SurfaceHit<T>{t2};
}

// Fixed: the nearer root in the window, else the farther (a ray from inside).
template <class T>
std::optional<SurfaceHit<T>> hit_fixed(const Ray<T>& r, const Vec3<T>& center, T radius) {
  T t1, t2;
  if (!roots(r, center, radius, t1, t2)) return std::nullopt;
  if (t1 >= r.tmin && t1 <= r.tmax) return SurfaceHit<T>{t1};
  if (t2 >= r.tmin && t2 <= r.tmax) return SurfaceHit<T>{t2};
  return std::nullopt;
}

}  // namespace ra::sphere_codeproject
