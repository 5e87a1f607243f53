// The textbook Möller–Trumbore test (Möller & Trumbore 1997, "Fast, Minimum
// Storage Ray/Triangle Intersection", section 2.4) as users write it, in float.
#pragma once
#include <cmath>
#include <optional>

#include <rayaudit/hit.h>
#include <rayaudit/ray.h>

namespace my {

// Barycentric u, v and t by Cramer's rule with the paper's EPSILON on the
// determinant and the paper's `u < 0 || u > 1` edge tests: each triangle is
// right on its own, but two triangles sharing an edge each round the edge's
// test their own way, so some rays pass between them.
inline std::optional<ra::TriangleHit<float>> textbook_moller(const ra::Rayf& r, const ra::Vec3f& v0,
                                                             const ra::Vec3f& v1, const ra::Vec3f& v2) {
  constexpr float kEpsilon = 1e-6f;
  const ra::Vec3f e1 = v1 - v0, e2 = v2 - v0;
  const ra::Vec3f p = cross(r.d, e2);
  const float det = dot(e1, p);
  if (std::fabs(det) < kEpsilon) return std::nullopt;
  const float inv_det = 1.0f / det;
  const ra::Vec3f s = r.o - v0;
  const float u = dot(s, p) * inv_det;
  if (u < 0.0f || u > 1.0f) return std::nullopt;
  const ra::Vec3f q = cross(s, e1);
  const float v = dot(r.d, q) * inv_det;
  if (v < 0.0f || u + v > 1.0f) return std::nullopt;
  const float t = dot(e2, q) * inv_det;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  return ra::TriangleHit<float>{t, u, v};
}

}  // namespace my
