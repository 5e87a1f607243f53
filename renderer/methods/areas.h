// seeds/001 ("badanie przecięcia promień-trójkąt", R. Kraus): plane hit with
// epsilon5 < t < infinity, then Heron's areas; two-sided, edges widened by epsilon3.
#pragma once
#include <cmath>
#include <limits>
#include <optional>

#include "point_barycentrics.h"

namespace ra::areas {

// The document's constants, by the names it uses (their values by their names).
// epsilon5: hits nearer than this are dropped, the text's cure for a secondary
// ray re-hitting its own surface; it also loses true hits closer than 1e-5.
// epsilon3: the area sum may exceed ABC by this much, so points outside by up
// to epsilon3 / (2 area(ABC)) in barycentric terms are accepted; the tolerance
// is absolute, so it is huge for small triangles and nothing for large ones.
inline constexpr double epsilon5 = 1e-5;
inline constexpr double epsilon3 = 1e-3;

// Heron's formula exactly as the listing's area(v1, v2, v3). The listing's
// bug, kept: for a point (nearly) on the line through two vertices the
// product p(p-a)(p-b)(p-c) is zero in exact arithmetic but can round below
// zero, and sqrt gives NaN; the listing's `sum > ABC + epsilon3` is then false,
// so a point on an edge's extension, far outside the triangle, is accepted
// (triangle_documents_test.cpp shows it).
template <class T>
T area(const Vec3<T>& v1, const Vec3<T>& v2, const Vec3<T>& v3) {
  const T a = length(v2 - v1);
  const T b = length(v3 - v1);
  const T c = length(v3 - v2);
  const T p = (a + b + c) / T(2);
  return std::sqrt(p * (p - a) * (p - b) * (p - c));
}

// The hit parameter if the document accepts the hit, nothing otherwise.
// Barycentrics are not part of the method: detail::DecidesT
// (point_barycentrics.h) computes them from the hit point after this decision.
template <class T>
std::optional<T> accept(const Ray<T>& r, const Vec3<T>& A, const Vec3<T>& B, const Vec3<T>& C, bool cull) {
  // The listing's T.N and T.d: the plane dot(N, x) + d = 0 through A. N need
  // not be unit: t does not depend on its length.
  const Vec3<T> N = cross(B - A, C - A);
  if (cull && detail::culled(r, N)) return std::nullopt;
  const T d = -dot(N, A);
  const T t = (-d - dot(N, r.o)) / dot(N, r.d);
  // The listing's test on a unit direction, so epsilon5 is a distance: with
  // our direction of any length, t |d| is that distance. A parallel ray gives
  // +-inf or NaN here and fails it.
  if (!(t * length(r.d) > T(epsilon5) && t < std::numeric_limits<T>::infinity())) return std::nullopt;
  if (!detail::in_window(r, t)) return std::nullopt;
  const Vec3<T> ip = r.at(t);
  const T abc = area(A, B, C);
  const T pbc = area(ip, B, C);
  const T apc = area(A, ip, C);
  const T abp = area(A, B, ip);
  if (pbc + apc + abp > abc + T(epsilon3)) return std::nullopt;
  return t;
}

}  // namespace ra::areas
