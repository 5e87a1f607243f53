// seeds/002 (topic 8, "Решение на системата"): Cramer's rule written with scalar
// triple products; two-sided; edges and vertices inclusive (0 <= l2, l3, l2 + l3 <= 1).
#pragma once
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::triple {

// The document's names: Det, H, lambda2, lambda3 (its t is printed as gamma).
// The system is A + l2 (B-A) + l3 (C-A) = O + t D, i.e. columns (B-A, C-A, -D).
template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& A, const Vec3<T>& B, const Vec3<T>& C, bool cull) {
  const Vec3<T> AB = B - A, AC = C - A, minusD = -r.d;
  const Vec3<T> n = cross(AB, AC);
  const T Det = dot(n, minusD);
  // Det = -(n.D): a front face (n against D) has Det > 0. Det == 0: parallel.
  if (cull ? !(Det > T(0)) : !(Det != T(0))) return std::nullopt;
  const Vec3<T> H = r.o - A;
  const T t = dot(n, H) / Det;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  const T lambda2 = dot(cross(H, AC), minusD) / Det;
  if (!(lambda2 >= T(0) && lambda2 <= T(1))) return std::nullopt;
  const T lambda3 = dot(cross(AB, H), minusD) / Det;
  if (!(lambda3 >= T(0) && lambda2 + lambda3 <= T(1))) return std::nullopt;
  return TriangleHit<T>{t, lambda2, lambda3};
}

template <class T>
bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return hit(r, a, b, c, cull).has_value();
}

}  // namespace ra::triple
