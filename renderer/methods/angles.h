// seeds/000 §2.1 ("metoda bazująca na kątach"): plane first, then the signs of
// (fa x fb).n, (fb x fc).n, (fc x fa).n; two-sided; edges widened by MINUS_ZERO.
#pragma once
#include <optional>

#include "point_barycentrics.h"

namespace ra::angles {

// The document's two constants, kept under its names (#define in the lab).
// MINUS_ZERO "rounds" the edges: a point is rejected only when a cross
// product's dot with the normal is below -0.0001, so points slightly outside
// are accepted. PLUS_ZERO is defined but not used by the listing; the plane
// step of lab I is not in the seed, so we use it where a "positive zero" is
// needed there: a ray whose direction makes |cos| < PLUS_ZERO with the plane's
// normal is treated as parallel (a miss).
inline constexpr double PLUS_ZERO = 0.00001;
inline constexpr double MINUS_ZERO = -0.0001;

// The hit parameter if the document accepts the hit, nothing otherwise.
// Barycentrics are not part of the method: detail::DecidesT
// (point_barycentrics.h) computes them from the hit point after this decision.
// The normal is normalised (the listing's MyPlane.ABC is the plane's normal),
// so (fa x fb).n is twice the signed area of PAB and MINUS_ZERO is an area
// tolerance: it admits points up to 1e-4 / |AB| outside edge AB.
template <class T>
std::optional<T> accept(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  const Vec3<T> n_raw = cross(b - a, c - a);  // n = (b - a) x (c - a), as in the text
  if (cull && detail::culled(r, n_raw)) return std::nullopt;
  const T len = length(n_raw);
  if (!(len > T(0))) return std::nullopt;  // degenerate triangle: no plane
  const Vec3<T> n = n_raw / len;
  // Plane step: parallel when |n.d| < PLUS_ZERO |d| (compared squared, no sqrt).
  const T denom = dot(n, r.d);
  if (denom * denom < T(PLUS_ZERO * PLUS_ZERO) * dot(r.d, r.d)) return std::nullopt;
  const T t = dot(n, a - r.o) / denom;
  if (!detail::in_window(r, t)) return std::nullopt;
  const Vec3<T> p = r.at(t);
  // Vectors from the crossing point to the vertices, as the listing's fa, fb, fc.
  const Vec3<T> fa = a - p, fb = b - p, fc = c - p;
  if (dot(cross(fa, fb), n) < T(MINUS_ZERO)) return std::nullopt;
  if (dot(cross(fb, fc), n) < T(MINUS_ZERO)) return std::nullopt;
  if (dot(cross(fc, fa), n) < T(MINUS_ZERO)) return std::nullopt;
  return t;
}

}  // namespace ra::angles
