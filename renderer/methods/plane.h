// Ray/plane for the plane dot(N, P) = offset with N of unit length, as
// POV-Ray's plane { N, offset } (objects: planes.cpp). Two-sided.
#pragma once
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::plane {

template <class T>
std::optional<SurfaceHit<T>> hit(const Ray<T>& r, const Vec3<T>& n, T offset) {
  const T denom = dot(n, r.d);
  if (denom == T(0)) return std::nullopt;  // parallel: never a hit, even in the plane
  const T t = (offset - dot(n, r.o)) / denom;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  return SurfaceHit<T>{t};
}

}  // namespace ra::plane
