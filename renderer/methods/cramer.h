// seeds/000 §2.2 (barycentric coordinates, Cramer's rule with scalars a..l):
// solves [a-b, a-c, d][beta gamma t]^T = a - o; strictly inside only (edges miss).
#pragma once
#include <optional>

#include "../hit.h"
#include "../ray.h"

namespace ra::cramer {

// The document's names: the matrix [a d g; b e h; c f i] holds the columns
// A - B, A - C and the direction; (j, k, l) = A - O; M is the determinant.
// One correction: the text prints t = (f(ak-jb) + e(jc-al) + d(bl-kc)) / M,
// which is -t (Cramer's rule for the third column gives the opposite sign;
// Shirley's FCG, which the lab follows, has the minus). As printed, every hit
// in front of the ray would come out behind it, so we use the minus sign.
template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& A, const Vec3<T>& B, const Vec3<T>& C, bool cull) {
  const T a = A.x - B.x, b = A.y - B.y, c = A.z - B.z;
  const T d = A.x - C.x, e = A.y - C.y, f = A.z - C.z;
  const T g = r.d.x, h = r.d.y, i = r.d.z;
  const T j = A.x - r.o.x, k = A.y - r.o.y, l = A.z - r.o.z;

  const T ei_minus_hf = e * i - h * f;
  const T gf_minus_di = g * f - d * i;
  const T dh_minus_eg = d * h - e * g;
  const T M = a * ei_minus_hf + b * gf_minus_di + c * dh_minus_eg;
  // M = ((B-A) x (C-A)).d, so a front face (normal against d) has M < 0.
  if (cull ? !(M < T(0)) : !(M != T(0))) return std::nullopt;

  const T ak_minus_jb = a * k - j * b;
  const T jc_minus_al = j * c - a * l;
  const T bl_minus_kc = b * l - k * c;
  const T t = -(f * ak_minus_jb + e * jc_minus_al + d * bl_minus_kc) / M;
  if (!(t >= r.tmin && t <= r.tmax)) return std::nullopt;
  const T gamma = (i * ak_minus_jb + h * jc_minus_al + g * bl_minus_kc) / M;
  if (!(gamma > T(0) && gamma < T(1))) return std::nullopt;
  const T beta = (j * ei_minus_hf + k * gf_minus_di + l * dh_minus_eg) / M;
  // Strict, as the text: beta > 0, gamma > 0, beta + gamma < 1.
  if (!(beta > T(0) && beta + gamma < T(1))) return std::nullopt;
  return TriangleHit<T>{t, beta, gamma};
}

template <class T>
bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return hit(r, a, b, c, cull).has_value();
}

}  // namespace ra::cramer
