// Self-intersection strategies for secondary (shadow and reflected) rays.
// eps: seeds/001 "Błędy numeryczne" (accept only t > 0.00001); pov: POV-Ray
// 3.7's t-windows (trace.cpp; ../shared/POVRAY.md); normal-offset: pbrt-v4's
// OffsetRayOrigin (offset along n by the hit point's error bound, then one ulp
// outward); ulp-offset: Wächter & Binder, Ray Tracing Gems ch. 6.
#pragma once
#include <cmath>
#include <cstdint>
#include <bit>
#include <limits>
#include <optional>
#include <string_view>

#include "ray.h"

namespace ra {

enum class SelfIntersection { eps, pov, normal_offset, ulp_offset };

inline std::optional<SelfIntersection> parse_self_intersection(std::string_view s) {
  if (s == "eps") return SelfIntersection::eps;
  if (s == "pov") return SelfIntersection::pov;
  if (s == "normal-offset") return SelfIntersection::normal_offset;
  if (s == "ulp-offset") return SelfIntersection::ulp_offset;
  return std::nullopt;
}
inline const char* self_intersection_name(SelfIntersection s) {
  switch (s) {
    case SelfIntersection::eps:
      return "eps";
    case SelfIntersection::pov:
      return "pov";
    case SelfIntersection::normal_offset:
      return "normal-offset";
    case SelfIntersection::ulp_offset:
      return "ulp-offset";
  }
  return "?";
}
constexpr const char* kSelfIntersectionNames = "eps, pov, normal-offset, ulp-offset";

// The document's fixed epsilon (seeds/001: "eps ... np. 0.00001").
inline constexpr double epsilon5 = 0.00001;
// POV-Ray 3.7: shadow rays ignore blockers outside (1e-3, dist - 1e-3);
// camera and reflected rays accept t >= 1e-4 (trace.cpp, MIN_ISECT_DEPTH).
inline constexpr double kPovShadowTolerance = 1e-3;
inline constexpr double kPovMinIsectDepth = 1e-4;

namespace detail {

// gamma(n) = n u / (1 - n u), the bound of n successive roundings (pbrt-v4).
template <class T>
constexpr T gamma(int n) {
  constexpr T u = std::numeric_limits<T>::epsilon() * T(0.5);
  return (n * u) / (1 - n * u);
}

// Moves every component of po one ulp along the sign of `dir` (none where it is 0).
template <class T>
Vec3<T> step_outward(Vec3<T> po, const Vec3<T>& dir) {
  for (int i = 0; i < 3; ++i) {
    if (dir[i] > 0)
      po[i] = std::nextafter(po[i], std::numeric_limits<T>::infinity());
    else if (dir[i] < 0)
      po[i] = std::nextafter(po[i], -std::numeric_limits<T>::infinity());
  }
  return po;
}

// Ray Tracing Gems ch. 6, "A Fast and Robust Method for Avoiding
// Self-Intersection": offset in integer ulps (int_scale 256) far from the
// origin, by float_scale 1/65536 in world units within 1/32 of it. The
// chapter is written for float; for double the integer step is scaled by
// 2^29 (the difference in mantissa bits) so the offset keeps the same
// relative size, which is conservative for double's smaller rounding.
template <class T>
Vec3<T> ulp_offset(const Vec3<T>& p, const Vec3<T>& n) {
  constexpr T origin = T(1) / T(32);
  constexpr T float_scale = T(1) / T(65536);
  Vec3<T> r;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(p[i]) < origin) {
      r[i] = p[i] + float_scale * n[i];
      continue;
    }
    if constexpr (sizeof(T) == 4) {
      const auto of = static_cast<std::int32_t>(T(256) * n[i]);
      auto bits = std::bit_cast<std::int32_t>(float(p[i]));
      bits += (p[i] < 0) ? -of : of;
      r[i] = T(std::bit_cast<float>(bits));
    } else {
      const auto of = static_cast<std::int64_t>(T(256) * T(536870912.0) * n[i]);
      auto bits = std::bit_cast<std::int64_t>(double(p[i]));
      bits += (p[i] < 0) ? -of : of;
      r[i] = T(std::bit_cast<double>(bits));
    }
  }
  return r;
}

}  // namespace detail

// A secondary ray leaving hit point p in unit direction dir.
//  n: the surface's geometric normal (either orientation: it is turned to
//     the side the ray leaves toward);
//  p_error: a per-component bound on |p - exact hit point| (pbrt-v4), used
//     by normal-offset only;
//  shadow: a shadow ray toward a light at distance light_distance from p
//     (tmax ends before the light); otherwise tmax is infinite.
template <class T>
Ray<T> spawn_ray(SelfIntersection s, const Vec3<T>& p, const Vec3<T>& p_error, Vec3<T> n, const Vec3<T>& dir,
                 bool shadow, T light_distance) {
  if (dot(n, dir) < 0) n = -n;
  const T inf = std::numeric_limits<T>::infinity();
  switch (s) {
    case SelfIntersection::eps:
      return {p, dir, T(epsilon5), shadow ? light_distance : inf};
    case SelfIntersection::pov:
      if (shadow) return {p, dir, T(kPovShadowTolerance), light_distance - T(kPovShadowTolerance)};
      return {p, dir, T(kPovMinIsectDepth), inf};
    case SelfIntersection::normal_offset: {
      const T d = dot(abs(n), p_error);
      const Vec3<T> offset = n * d;
      // One ulp outward along n's signs, not the offset's: with a zero error
      // bound (a hit on an axis-aligned triangle, e.g. z = 0 for all three
      // vertices) the offset is zero and the origin would stay ON the
      // surface, which the window [0, tmax] then meets again at t = 0.
      const Vec3<T> po = detail::step_outward(p + offset, n);
      // The light is still at p + dir * light_distance; shorten by the offset.
      const T tmax = shadow ? (light_distance - length(po - p)) * (T(1) - detail::gamma<T>(3)) : inf;
      return {po, dir, T(0), tmax};
    }
    case SelfIntersection::ulp_offset: {
      const Vec3<T> po = detail::ulp_offset(p, n);
      const T tmax = shadow ? (light_distance - length(po - p)) * (T(1) - detail::gamma<T>(3)) : inf;
      return {po, dir, T(0), tmax};
    }
  }
  return {p, dir, T(0), inf};
}

// pbrt-v4's bound on the error of a triangle hit point computed from
// barycentrics: gamma(7) * (|b0 A| + |b1 B| + |b2 C|).
template <class T>
Vec3<T> triangle_point_error(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, T b1, T b2) {
  const T b0 = T(1) - b1 - b2;
  return (abs(a * b0) + abs(b * b1) + abs(c * b2)) * detail::gamma<T>(7);
}

// pbrt-v4's bound for a point computed as o + t d and reprojected onto a
// sphere: gamma(5) * |p - center| componentwise, plus the centre's own size.
// It holds only for the reprojected point (reproject_onto_sphere): o + t d
// itself carries the error of the method's t, which no bound of this form
// covers (a quadratic's root can lose many digits).
template <class T>
Vec3<T> sphere_point_error(const Vec3<T>& p) {
  return abs(p) * detail::gamma<T>(5);
}

// pbrt-v4's reprojection (Sphere::Intersect: pHit *= radius / Distance(pHit,
// 0)): the hit point moved along its radius onto the sphere, so that its
// error is sphere_point_error's, whatever the error of t was.
template <class T>
Vec3<T> reproject_onto_sphere(const Vec3<T>& p, const Vec3<T>& center, T radius) {
  const Vec3<T> r = p - center;
  const T len = length(r);
  return len > T(0) ? center + r * (radius / len) : p;
}

}  // namespace ra
