// exact: ray/triangle decisions equal to exact arithmetic on the given float
// or double inputs, at floating-point speed. A floating-point filter with
// proven error bounds decides almost every test; the rest go to exact
// rational arithmetic (GMP, exact.cpp).
//
// Sources. The decision is the Plücker / scalar-triple-product test on
// vertices translated to the ray origin, as the watertight method (Woop,
// Benthin, Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013)
// evaluates it after its shear, here without the shear and with its signs
// certified instead of trusted. The certification is a static-plus-dynamic
// filter in the manner of Shewchuk ("Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates", DCG 18, 1997) and of
// pbrt-v4's gamma(n) bounds (Pharr, Jakob, Humphreys, "Physically Based
// Rendering", 4th ed., 6.8: gamma(n) = n u / (1 - n u), u the unit roundoff,
// bounds n chained roundings); error analysis of sums of products as Higham,
// "Accuracy and Stability of Numerical Algorithms", 2nd ed., 3.1.
//
// Semantics (the audit oracle's, validation/exact/oracle.h): the triangle is
// closed (edges and vertices belong to it), the window is the closed
// [max(tmin, 0), tmax]; inputs are the exact values of their floats or
// doubles; a ray with a non-finite input or an empty window misses;
// degenerate triangles and rays in the triangle's plane miss (the audit
// accepts either answer there).
//
// Derivation. Translate: A' = A - o, B' = B - o, C' = C - o. The line
// o + t d meets the triangle's plane at the point with barycentrics
// (U, V, W) / det, where
//   U = d . (B' x C'),  V = d . (C' x A'),  W = d . (A' x B')
// are the signed volumes of the line with each edge (Plücker products), and
//   det = U + V + W = d . n,  n = (B - A) x (C - A)
// (expand (B'-A') x (C'-A') = B'xC' + C'xA' + A'xB'). The closed triangle is
// met iff U, V, W are not of opposite signs and not all zero (then det has
// their common sign and is not zero). The hit distance solves
// o + t d = (U A + V B + W C) / det: dotting t d = (U A' + V B' + W C') / det
// with n, and n . A' = n . B' = n . C' (the plane), gives
//   t = N / det,  N = n . A' = [A', B', C'] (the triple product).
// The decision is the signs of U, V, W and of N - tlo det, thi det - N;
// nothing else. Front face: det = n . d < 0 (cull rejects det > 0).
//
// Guarantees.
//  - Every hit/miss verdict is that of exact arithmetic (above). Boundary
//    crossings (a zero among U, V, W) are hits, so a ray through an edge or
//    vertex shared by triangles hits all of them: no leak, ever.
//  - t is CORRECTLY ROUNDED (round to nearest, ties to even) to T: the fast
//    path returns it only when its whole error enclosure rounds to one value,
//    the exact path rounds the exact rational with MPFR. So the scalar form,
//    the BVH's 4-lane form and every machine return the same bits.
//  - b1 = V / det, b2 = W / det, clamped to [0, 1]; from the filter they are
//    within (errV + b errD) / |det| + 2u of exact (errV, errD the bounds
//    below, u of the compute type): relative to the triangle's size, about
//    2^-46 (double rays) or 2^-24 (float) times |d| max|P - o|^2 / |d . n|,
//    so larger for grazing rays and small far triangles; from the exact path
//    within 1 ulp of T.
//
// The filter (stage 1, `signs`), in double for both precisions. The
// products are Plücker values on translated vertices b' = fl(B - o):
//   b' = B'(1 + e), |e| <= u (exact where the difference is subnormal);
//   U~ = fl(d . fl(b' x c')): each term d_i b'_j c'_k passes through at most
//     2 (translations) + 1 (product) + 1 (cross difference) + 1 (times d_i)
//     + 2 (the sum of three) = 7 roundings, so (Higham 3.1, pbrt's gamma)
//     |U~ - U| <= gamma(7) sum_i |d_i| (|B'_j C'_k| + |B'_k C'_j|)
//              <= gamma(7) / ((1 - u)^2 (1 - gamma(4))) * 2 s_d m_b m_c
//     with s_d = |d|_1, m_b = max_i |b'_i| (computed; their own 4 roundings
//     are the (1 - gamma(4))), and gamma(7) / (...) < 8 u: errU = 16 u s_d
//     m_b m_c = 2^-49 s_d m_b m_c (a power of two: the bound's product is
//     exact but for its own rounding, covered by the margin 8u -> 16u/2).
//   Range: float inputs in double never overflow or underflow (differences
//     of floats are multiples of 2^-149 below 2^129; products of three lie
//     in [2^-447, 2^390], far inside double's normal range), so the bound
//     is complete. Double inputs are filtered in double only while s_d, m_a,
//     m_b, m_c <= 2^330 (every product of three then < 2^994: no overflow);
//     underflow adds at most 2^-1075 a rounding, amplified by |d_i| <=
//     2^330, so the bound gains tau = 2^-736 >= 2^(330+5) 2^-1075. Beyond
//     the range, or where a sign is not certified, stage 2 redoes the signs
//     in long double (x87, u = 2^-64, exponent to 2^16383: products of three
//     or four doubles neither overflow nor underflow, tau = 0), and stage 3
//     is exact.
// Certified: |U~| > errU gives sign(U). Two certified opposite signs: a
// miss (most misses end here). All three certified one sign: a crossing
// strictly inside; anything else goes on.
//
// The distance (stage 1b, `enclose_t`), in double for float inputs and long
// double for double inputs (both range-safe as above), from the well
// conditioned form t = (n . A') / (n . d) with n from the triangle's own
// edges (independent of the ray's distance, unlike [A', B', C']):
//   e1 = fl(B - A), e2 = fl(C - A), n~ = fl(e1 x e2): each term of N = n.A'
//   passes through 2 + 1 + 1 (n) + 1 (A') + 1 (product) + 2 (sum) = 8
//   roundings, of D = n.d through 7, so
//     |N~ - N| <= gamma(8) sum_i Pn_i |A'_i|,  |D~ - D| <= gamma(7) sum_i Pn_i |d_i|,
//   Pn_i = |e1_j e2_k| + |e1_k e2_j|; with the same accounting of computed
//   magnitudes as above, errN = 16 u PN~, errD = 16 u PD~.
//   With a = errN / |N~| <= 1/4 and b = errD / |D~| <= 1/4, t~ = fl(N~ / D~):
//     |t / t~ - 1| <= (a + b + u) / ((1 - b)(1 - u)) <= 2 (a + b) + 3u,
//   so t lies in [lo, hi] = t~ -+ |t~| (2 (a + b) + 16u): computing the
//   width costs at most 4 roundings of a value <= 1.01 |t~| and lo, hi one
//   each of a value <= 2|t~|, 4u + 2u + ... < 13u, covered by 16u - 3u. The window is decided
//   when [lo, hi] lies inside it or outside it. Rounding to nearest is
//   monotone, so when T(lo) == T(hi) every value in [lo, hi], t among them,
//   rounds to that one T: t correctly rounded. Otherwise stage 3.
//   (Float: u = 2^-53 leaves 29 bits for the rounding decision; double:
//   u = 2^-64 leaves 11, so near 1 in 2^11 / (30 cond) double hits ask for
//   the exact path, cond = 1 / |cos| of the ray's angle to the normal.)
//
// Exact fallback (stage 3, exact.cpp): GMP rationals (mpq_t, libgmp-dev)
// over the inputs' exact values, the same formulas; t rounded by MPFR
// (mpfr_set_q + mpfr_subnormalize in T's exponent range: correct rounding
// including subnormals and overflow). Why GMP and not Shewchuk expansions:
// expansions are exact only while no partial product underflows or
// overflows, so any finite input would still need a range reduction with
// its own proofs; mpq has no range and no proof beyond the algebra above,
// and it runs only for the few tests the filter leaves (its ~1-3 us does
// not show in the mean). Thread-local scratch: no allocation once warm.
//
// Fallback counters (thread-local, `fallbacks()`): how many tests took
// stage 2 and stage 3, for the audit's per-family rates.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "../hit.h"
#include "../ray.h"

namespace ra::exact {

// Tests on this thread that went past the double filter.
struct Fallbacks {
  std::uint64_t extended = 0;  // signs redone in long double (double inputs only)
  std::uint64_t exact = 0;     // decided by GMP
};
Fallbacks& fallbacks();

// Stage 3: the whole test in exact rational arithmetic (exact.cpp).
template <class T>
std::optional<TriangleHit<T>> hit_exact(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                        bool cull);
extern template std::optional<TriangleHit<float>> hit_exact(const Ray<float>&, const Vec3<float>&,
                                                            const Vec3<float>&, const Vec3<float>&, bool);
extern template std::optional<TriangleHit<double>> hit_exact(const Ray<double>&, const Vec3<double>&,
                                                             const Vec3<double>&, const Vec3<double>&, bool);

namespace detail {

// The unit roundoff u of C (half the machine epsilon): 2^-53, 2^-64.
template <class C>
constexpr C unit_roundoff() {
  return std::numeric_limits<C>::epsilon() / C(2);
}

template <class C>
inline C max3(C x, C y, C z) {
  return std::max(x, std::max(y, z));
}

// The filter's verdict on the signs of U, V, W.
enum class Signs { miss, inside, undecided };

// Stage 1/2: signs of U, V, W in compute type C, with the bound of the
// header: err = 16 u s_d m_p m_q + tau. `limit`: the largest s_d and m
// allowed (range guard; infinity where C is range-safe for T). U, V, W
// and s (their common sign: +1 det > 0, -1 det < 0) are set for `inside`.
template <class C, class T>
[[gnu::always_inline]] inline Signs signs(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                          C limit, C tau, C& U, C& V, C& W, int& s) {
  const C ox = C(r.o.x), oy = C(r.o.y), oz = C(r.o.z);
  const C dx = C(r.d.x), dy = C(r.d.y), dz = C(r.d.z);
  const C ax = C(a.x) - ox, ay = C(a.y) - oy, az = C(a.z) - oz;
  const C bx = C(b.x) - ox, by = C(b.y) - oy, bz = C(b.z) - oz;
  const C cx = C(c.x) - ox, cy = C(c.y) - oy, cz = C(c.z) - oz;
  // U = d . (B' x C'), V = d . (C' x A'), W = d . (A' x B')
  U = dx * (by * cz - bz * cy) + dy * (bz * cx - bx * cz) + dz * (bx * cy - by * cx);
  V = dx * (cy * az - cz * ay) + dy * (cz * ax - cx * az) + dz * (cx * ay - cy * ax);
  W = dx * (ay * bz - az * by) + dy * (az * bx - ax * bz) + dz * (ax * by - ay * bx);
  const C sd = std::abs(dx) + std::abs(dy) + std::abs(dz);
  const C ma = max3(std::abs(ax), std::abs(ay), std::abs(az));
  const C mb = max3(std::abs(bx), std::abs(by), std::abs(bz));
  const C mc = max3(std::abs(cx), std::abs(cy), std::abs(cz));
  // Range guard (also false for NaN: then nothing is certified below).
  if (!(max3(ma, mb, mc) <= limit && sd <= limit)) return Signs::undecided;
  constexpr C k = C(16) * unit_roundoff<C>();
  const C ksd = k * sd;
  const C eU = ksd * mb * mc + tau, eV = ksd * mc * ma + tau, eW = ksd * ma * mb + tau;
  const bool pu = U > eU, nu = U < -eU, pv = V > eV, nv = V < -eV, pw = W > eW, nw = W < -eW;
  if ((pu | pv | pw) & (nu | nv | nw)) return Signs::miss;  // two certified opposite signs
  if (pu & pv & pw) return s = 1, Signs::inside;
  if (nu & nv & nw) return s = -1, Signs::inside;
  return Signs::undecided;
}

// What the distance stage settled.
enum class Dist { out, in, undecided };

// Stage 1b: t = (n . A') / (n . d) in C with its enclosure (header); `out`
// when the window is certainly missed, `in` with t_out correctly rounded
// to T (when need_t) when it is certainly met.
template <class C, class T>
[[gnu::always_inline]] inline Dist enclose_t(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                             bool need_t, T& t_out) {
  const C ax = C(a.x), ay = C(a.y), az = C(a.z);
  const C e1x = C(b.x) - ax, e1y = C(b.y) - ay, e1z = C(b.z) - az;
  const C e2x = C(c.x) - ax, e2y = C(c.y) - ay, e2z = C(c.z) - az;
  const C nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  const C px = std::abs(e1y * e2z) + std::abs(e1z * e2y), py = std::abs(e1z * e2x) + std::abs(e1x * e2z),
          pz = std::abs(e1x * e2y) + std::abs(e1y * e2x);
  const C qx = ax - C(r.o.x), qy = ay - C(r.o.y), qz = az - C(r.o.z);
  const C dx = C(r.d.x), dy = C(r.d.y), dz = C(r.d.z);
  const C N = nx * qx + ny * qy + nz * qz;
  const C D = nx * dx + ny * dy + nz * dz;
  constexpr C u = unit_roundoff<C>(), k = C(16) * u;
  const C eN = k * (px * std::abs(qx) + py * std::abs(qy) + pz * std::abs(qz));
  const C eD = k * (px * std::abs(dx) + py * std::abs(dy) + pz * std::abs(dz));
  const C aN = std::abs(N), aD = std::abs(D);
  if (!(aN > C(4) * eN && aD > C(4) * eD)) return Dist::undecided;  // t near 0, or grazing (also NaN)
  const C t = N / D;
  const C w = std::abs(t) * (C(2) * (eN / aN + eD / aD) + C(16) * u);
  const C lo = t - w, hi = t + w;
  const C tlo = std::max(C(r.tmin), C(0)), thi = C(r.tmax);
  if (hi < tlo || lo > thi) return Dist::out;
  if (!(lo >= tlo && hi <= thi)) return Dist::undecided;  // on the window's edge (or a NaN window)
  if (need_t) {
    const T rl = T(lo), rh = T(hi);
    if (rl != rh) return Dist::undecided;  // t near a rounding boundary
    t_out = rl;
  }
  return Dist::in;
}

// The barycentrics from the certified Plücker values, clamped to [0, 1].
template <class C, class T>
[[gnu::always_inline]] inline TriangleHit<T> finish(T t, C U, C V, C W) {
  const C inv = C(1) / (U + V + W);
  const C b1 = std::min(std::max(V * inv, C(0)), C(1)), b2 = std::min(std::max(W * inv, C(0)), C(1));
  return TriangleHit<T>{t, T(b1), T(b2)};
}

// The test; need_t = false for any-hit (the verdict only).
template <class T>
[[gnu::always_inline]] inline std::optional<TriangleHit<T>> test(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b,
                                                                const Vec3<T>& c, bool cull, bool need_t) {
  constexpr bool kFloat = sizeof(T) == sizeof(float);
  // Double inputs: the double filter's range guard and underflow term.
  constexpr double kLimit = kFloat ? std::numeric_limits<double>::infinity() : 0x1p330;
  constexpr double kTau = kFloat ? 0.0 : 0x1p-736;
  double U, V, W;
  int s = 0;
  const Signs sg = signs<double>(r, a, b, c, kLimit, kTau, U, V, W, s);
  if (sg == Signs::miss) return std::nullopt;
  if (sg == Signs::inside) {
    if (cull && s > 0) return std::nullopt;
    T t{};
    using C = std::conditional_t<kFloat, double, long double>;
    const Dist ds = enclose_t<C>(r, a, b, c, need_t, t);
    if (ds == Dist::out) return std::nullopt;
    if (ds == Dist::in) return finish<double, T>(t, U, V, W);
    ++fallbacks().exact;
    return hit_exact(r, a, b, c, cull);
  }
  if constexpr (!kFloat) {
    ++fallbacks().extended;
    long double Ul, Vl, Wl;
    const Signs sl = signs<long double>(r, a, b, c, std::numeric_limits<long double>::infinity(), 0.0L, Ul, Vl, Wl, s);
    if (sl == Signs::miss) return std::nullopt;
    if (sl == Signs::inside) {
      if (cull && s > 0) return std::nullopt;
      T t{};
      const Dist ds = enclose_t<long double>(r, a, b, c, need_t, t);
      if (ds == Dist::out) return std::nullopt;
      if (ds == Dist::in) return finish<long double, T>(t, Ul, Vl, Wl);
    }
  }
  ++fallbacks().exact;
  return hit_exact(r, a, b, c, cull);
}

}  // namespace detail

template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                  bool cull) {
  return detail::test(r, a, b, c, cull, true);
}

template <class T>
bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return detail::test(r, a, b, c, cull, false).has_value();
}

}  // namespace ra::exact
