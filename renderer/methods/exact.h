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
//  - t is FAITHFULLY ROUNDED to T: one of the two T values bracketing the
//    exact t (at most 1 ulp from it), and correctly rounded (to nearest)
//    whenever the filter's whole enclosure of t rounds to one value (float
//    rays, computed in double: all but about 1 in 2^20; double rays, in long
//    double: about 9 in 10), on the double-word stage and on the exact path
//    (MPFR). The
//    value is a deterministic function of the inputs (the same operations
//    in the same order), so the direct and the prepared forms return the
//    same bits (exact_test.cpp checks it).
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
//     |t / t~ - 1| <= (a + b + u + bu) / ((1 - b)(1 - u)) <= K (a + b + 2u),
//   K = 2, or 1 + 2^-19 when a, b <= 2^-20 (almost always). The certificate
//   (beside enclose_t) multiplies through by |D~| instead of dividing, and
//   compares t~'s offset delta = t~ - q from q = T(t~) (exact: t~'s low
//   bits) and the enclosure's half-width with q's ulps on either side: when
//   the enclosure lies strictly between q's neighbours, t does, so q is
//   faithful (and correctly rounded whenever the enclosure also lies within
//   q's half-ulps, as it does for all but a few of them: see the measured
//   rates in README.md), and the window [tlo, thi] (T values) is decided by
//   comparing q with its ends. Where the enclosure is wider than an ulp,
//   the window is still decided when it lies wholly outside it (or, any-hit,
//   inside). Otherwise, for double inputs, stage 2b (exact.cpp,
//   t_double_word) recomputes N and D in double-word arithmetic from exact
//   differences (relative error ~2^-100 cond) and rounds t correctly; only
//   what that cannot settle (t within ~2^-95 of a rounding boundary or of a
//   window end, or inputs beyond 2^250) goes to stage 3. (Float: u = 2^-53
//   leaves 29 bits for the rounding decision; double: u = 2^-64 leaves 11:
//   the enclosure's half-width, about 2^-60 (PN / |N| + PD / |D|) |t|, where
//   PD / |D| ~ 1 / |cos| of the ray's angle to the normal, passes half an
//   ulp only where those conditions reach ~2^6.) The first form of this stage rounded both ends of the enclosure
//   to T and divided for its width: 1.7x watertight's ns on the kernel
//   bench's double hits against 1.4x now.
//
// Exact fallback (stage 3, exact.cpp): GMP rationals (mpq_t, libgmp-dev)
// over the inputs' exact values: U, V, W as above, det = U + V + W and
// N = [A', B', C'] (the triple product, no edges needed); t rounded by MPFR
// (mpfr_set_q + mpfr_subnormalize in T's exponent range: correct rounding
// including subnormals and overflow). Why GMP and not Shewchuk expansions:
// expansions are exact only while no partial product underflows or
// overflows, so any finite input would still need a range reduction with
// its own proofs; mpq has no range and no proof beyond the algebra above,
// and it runs only for the few tests the filter leaves (its ~1-3 us does
// not show in the mean). Thread-local scratch: no allocation once warm.
//
// Fallback counters (`fallbacks()`): how many tests took stage 2 and stage
// 3, for the audit's per-family rates (exact_method_audit_test prints them).
// Measured (2-core shared machine; renderer/methods/README.md has the
// table): `rayaudit audit --methods exact --rays 1000000` 0 in every error
// column, float and double (t at most 1 ulp from the oracle's); kernel
// bench (hit=50, back=50) 1.28x / 1.05x watertight's ns per test in float
// without / with culling, 1.44x / 1.18x in double (1.89x / 1.69x before the
// division-free certificate, 1.61x / 1.51x before the stored normal pairs
// and the half-ulp certificate); crack maps 0 leaks, 0 false pixels. The
// BVH's leaves run
// stage 1 four triangles at a time (exact_simd.h), answering as this code.
#pragma once
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "../hit.h"
#include "../ray.h"

namespace ra::exact {

// Tests (all threads, since the start) that went past the double filter:
// counted with relaxed atomics on those paths only, so the filter's own
// path pays nothing.
struct Fallbacks {
  std::uint64_t extended = 0;  // double inputs: signs redone in long double, or t in double-word
  std::uint64_t exact = 0;     // decided by GMP
};
Fallbacks fallbacks();
void count_extended();
void count_exact();

// Stage 3: the whole test in exact rational arithmetic (exact.cpp).
template <class T>
std::optional<TriangleHit<T>> hit_exact(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                        bool cull);
extern template std::optional<TriangleHit<float>> hit_exact(const Ray<float>&, const Vec3<float>&, const Vec3<float>&,
                                                            const Vec3<float>&, bool);
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
  const bool pu = U > eU, nu = U<-eU, pv = V> eV, nv = V<-eV, pw = W> eW, nw = W < -eW;
  if ((pu | pv | pw) & (nu | nv | nw)) return Signs::miss;  // two certified opposite signs
  if (pu & pv & pw) return s = 1, Signs::inside;
  if (nu & nv & nw) return s = -1, Signs::inside;
  return Signs::undecided;
}

// What the distance stage settled.
enum class Dist { out, in, undecided };

// The triangle's part of stage 1b, the same for every ray (the prepared
// form stores it): the normal n = e1 x e2 in C from edges rounded once in
// C, and the permanents Pn_i = |e1_j e2_k| + |e1_k e2_j| in double (SSE,
// cheaper than x87 where C is long double): their factors are differences
// rounded once (relative error <= 2^-53), then <= 5 roundings: within
// (1 + 2^-50) of the permanents of exact values (the 1 + 2^-48 below).
// Double inputs: the permanents are sound only without underflow or
// overflow, so every factor must be 0 or within [2^-300, 2^300] (float
// inputs always are, as stage 1's range note says); otherwise pn[0] is NaN
// and stage 1b never decides.
template <class C>
struct Edges {
  C n[3];
  double pn[3];
  C normal(int i) const { return n[i]; }
  double normal_double(int i) const { return double(n[i]); }
};

// The prepared form's copy of them. In long double, n is kept as two
// doubles whose sum is n exactly: an 80-bit load is microcoded (several
// times a double's), and the hit path of the prepared double kernel loads
// three. hi = n rounded to double, lo = n - hi (exact by Sterbenz: hi is
// within a double's ulp of n; at most 12 bits, so a double holds it), and
// hi + lo in long double is n again. The range: with tame edges (below)
// each nonzero component is at least 2^-666 (a difference of two products
// of factors >= 2^-301, 64-bit significands) and at most 2^602, so hi
// and lo are normal doubles; with untamed edges pn[0] is NaN and stage 1b
// decides nothing, whatever n holds.
template <class C>
struct StoredEdges : Edges<C> {
  static StoredEdges from(const Edges<C>& e) { return {e}; }
};
template <>
struct StoredEdges<long double> {
  double nh[3], nl[3];
  double pn[3];
  long double normal(int i) const { return static_cast<long double>(nh[i]) + static_cast<long double>(nl[i]); }
  double normal_double(int i) const { return nh[i]; }
  static StoredEdges from(const Edges<long double>& e) {
    StoredEdges s;
    for (int i = 0; i < 3; ++i) {
      s.nh[i] = double(e.n[i]);
      s.nl[i] = double(e.n[i] - static_cast<long double>(s.nh[i]));
      s.pn[i] = e.pn[i];
    }
    return s;
  }
};
inline bool tame(double x) { return (x == 0) | ((std::abs(x) >= 0x1p-300) & (std::abs(x) <= 0x1p300)); }
template <class C, class T>
[[gnu::always_inline]] inline Edges<C> edges(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  const C ax = C(a.x), ay = C(a.y), az = C(a.z);
  const C e1x = C(b.x) - ax, e1y = C(b.y) - ay, e1z = C(b.z) - az;
  const C e2x = C(c.x) - ax, e2y = C(c.y) - ay, e2z = C(c.z) - az;
  Edges<C> e;
  e.n[0] = e1y * e2z - e1z * e2y, e.n[1] = e1z * e2x - e1x * e2z, e.n[2] = e1x * e2y - e1y * e2x;
  const double fe1x = double(b.x) - double(a.x), fe1y = double(b.y) - double(a.y), fe1z = double(b.z) - double(a.z);
  const double fe2x = double(c.x) - double(a.x), fe2y = double(c.y) - double(a.y), fe2z = double(c.z) - double(a.z);
  e.pn[0] = std::abs(fe1y * fe2z) + std::abs(fe1z * fe2y);
  e.pn[1] = std::abs(fe1z * fe2x) + std::abs(fe1x * fe2z);
  e.pn[2] = std::abs(fe1x * fe2y) + std::abs(fe1y * fe2x);
  if constexpr (sizeof(T) == sizeof(double))
    if (!(tame(fe1x) && tame(fe1y) && tame(fe1z) && tame(fe2x) && tame(fe2y) && tame(fe2z)))
      e.pn[0] = std::numeric_limits<double>::quiet_NaN();
  return e;
}

// Stage 1b: t = (n . A') / (n . d) in C with its enclosure (header); `out`
// when the window is certainly missed, `in` with t_out (when need_t)
// faithfully rounded to T (correctly, where the enclosure allows) when it
// is certainly met.
//
// The certificate, without a division or a rounding of the enclosure's
// ends (both cost more than the x87 arithmetic itself). Let t~ = fl_C(N~ /
// D~), q = T(t~) and delta = t~ - q, exact in C and then in double (the
// low 11 (double inputs) or 29 (float) bits of t~; |q| >= 2^-900, or 2^-100
// for float, keeps it normal). With a = eN / |N~|, b = eD / |D~| <= 1/4,
//   |t / t~ - 1| <= rho = (a + b + u + bu) / ((1 - b)(1 - u)),
// at most K (a + b + 2u) with K = 1 + 2^-19 when a, b <= 2^-20 and K = 2
// otherwise. As |t~| = |N~ / D~| (1 + g), |g| <= u, and |t~| <= |q| (1 +
// 2^-23), |D~| <= aD (1 + 2^-52) (aD = |D~| rounded to double):
//   rho |t~| |D~| <= K (eN + eD |q| + 2u |q| aD) (1 + 2^-20) <= Y,
// Y computed in double with the factor 1 + 2^-17 (its 5 roundings of
// positive terms, 2^-50, inside). Then |t - t~| <= Y / |D~|, and t lies
// strictly between q's neighbours, at up = ulp(q) away from zero and down =
// ulp(q) towards it (ulp / 2 when |q| is a power of two), when
//   s delta + Y / |D~| < up  and  Y / |D~| - s delta < down  (s = sign q),
// that is Y < (up - s delta) |D~| and Y < (down + s delta) |D~|: the
// differences are exact (12 or 31 bits at q's ulp scale, both positive as
// |delta| <= half an ulp), and the products are rounded once each, covered
// by comparing with them times 1 - 2^-40 (|D~| >= aD (1 - 2^-53)). t is
// then within 1 ulp of q (faithful; correctly rounded when the same holds
// with half-ulps), and, q and the window's ends being T values, t >= tlo
// when q > tlo (t > prev(q) >= tlo) and t < tlo when q < tlo (t < next(q)
// <= tlo); likewise for thi. A q equal to a window end is left undecided.
// Tested first without delta: q = T(t~) rounded to nearest puts t~ within
// half of q's gaps (down / 2 below, up / 2 above), so Y < (down / 2) |D~|
// (down <= up) alone puts t strictly between q's neighbours, and delta,
// the return trip of q to the compute type, is needed only for the
// enclosures between half an ulp and an ulp wide: the same verdicts, and
// the audit's fallback rates unchanged.
// Where the certificate fails (the enclosure wider than an ulp: grazing
// rays, about cond > 2^5 for double inputs), the window may still be missed
// by far: t lies within |t~| rho <= Y / (aD (1 - 2^-52)), compared with a
// factor 1 + 2^-30 on the division's rounding.
template <class C, class T, class E>
[[gnu::always_inline]] inline Dist enclose_t(const Ray<T>& r, const Vec3<T>& a, const E& e, bool need_t, T& t_out) {
  const C qx = C(a.x) - C(r.o.x), qy = C(a.y) - C(r.o.y), qz = C(a.z) - C(r.o.z);
  const C n0 = e.normal(0), n1 = e.normal(1), n2 = e.normal(2);
  const C N = n0 * qx + n1 * qy + n2 * qz;
  const C D = n0 * C(r.d.x) + n1 * C(r.d.y) + n2 * C(r.d.z);
  const double fqx = double(a.x) - double(r.o.x), fqy = double(a.y) - double(r.o.y), fqz = double(a.z) - double(r.o.z);
  const double PN = e.pn[0] * std::abs(fqx) + e.pn[1] * std::abs(fqy) + e.pn[2] * std::abs(fqz);
  const double PD =
      e.pn[0] * std::abs(double(r.d.x)) + e.pn[1] * std::abs(double(r.d.y)) + e.pn[2] * std::abs(double(r.d.z));
  // The bounds in double: |N~|, |D~| rounded to double lose 2^-53
  // relative, covered by the factors 1 + 2^-40.
  constexpr C u = unit_roundoff<C>();
  constexpr double k = double(16 * u) * (1 + 0x1p-48);
  // Double inputs: the ray's factors |fq_i|, |d_i| are not range-checked
  // (six checks cost 4% of the kernel). One that overflows makes PN or PD
  // infinite or NaN, and nothing is certified below: every test compares
  // with them and fails. Underflow in a product pn_i |fq_i| or pn_i |d_i|
  // loses at most 2^-1075 each, so 16 u times the permanents exceeds k PN
  // by at most 16 u 3 2^-1075 < 2^-1130 beyond what k's 2^-48 covers.
  // Where k PN is below 2^-1021, it is itself off by at most 2^-1075
  // (underflow) and the sum below by 2^-1074 (rounding), so adding 2^-1073
  // leaves eN at least k PN + 2^-1075; above 2^-1021, 2^-49 of k PN is
  // over 2^-1070. Likewise eD. Float inputs never underflow here.
  constexpr double kUnder = sizeof(T) == sizeof(double) ? 0x1p-1073 : 0.0;
  const double eN = k * PN + kUnder, eD = k * PD + kUnder;
  const double aN = double(std::abs(N)), aD = double(std::abs(D));
  const T tlo = std::max(r.tmin, T(0)), thi = r.tmax;
  if (!(aN > 4 * (1 + 0x1p-40) * eN && aD > 4 * (1 + 0x1p-40) * eD)) {
    // t near 0 (N within its error bound), grazing, or untamed (NaN). With
    // D certain, |t| <= (aN (1 + 2^-52) + eN) / (aD (1 - 2^-53) - eD): a
    // window starting above that is missed (a shadow ray leaving the
    // surface, against the triangles it leaves from). The factors 1 -+
    // 2^-40 cover those and the three roundings here (eD < aD / 4).
    if (aD > 4 * (1 + 0x1p-40) * eD && (aN + eN) * (1 + 0x1p-40) < (aD - eD) * double(tlo) * (1 - 0x1p-40))
      return Dist::out;
    return Dist::undecided;
  }
  const double K = aN > 0x1p20 * (1 + 0x1p-40) * eN && aD > 0x1p20 * (1 + 0x1p-40) * eD ? 1 + 0x1p-19 : 2;
  const C t = N / D;
  const T q = T(t);
  const double aq = std::abs(double(q));
  constexpr double kLow = sizeof(T) == sizeof(float) ? 0x1p-100 : 0x1p-900;
  constexpr double kHigh = sizeof(T) == sizeof(float) ? 0x1p100 : 0x1p1000;
  if (!(aq >= kLow && aq <= kHigh)) return Dist::undecided;  // t tiny, huge or NaN: the later stages
  // ulp(q): 2^e (|q| in [2^e, 2^(e+1)), its exponent bits) times 2^-52 or 2^-23.
  constexpr std::uint64_t kExp = 0x7FF0000000000000u;
  const double pe = std::bit_cast<double>(std::bit_cast<std::uint64_t>(aq) & kExp);
  const double up = pe * (sizeof(T) == sizeof(float) ? 0x1p-23 : 0x1p-52);
  const double down = aq == pe ? up * 0.5 : up;
  const double Y = K * (eN + eD * aq + 2 * double(u) * aq * aD) * (1 + 0x1p-17);
  // First without delta (half an ulp either side holds t~, q being t~
  // rounded to nearest): no return trip of q to the x87 stack on the
  // common path. Then with it, for the enclosures between half an ulp and
  // an ulp wide.
  const bool narrow = Y < down * 0.5 * aD * (1 - 0x1p-40);
  const double sdelta = narrow ? 0 : q < 0 ? double(C(q) - t) : double(t - C(q));
  if (!narrow && !(Y < (up - sdelta) * aD * (1 - 0x1p-40) && Y < (down + sdelta) * aD * (1 - 0x1p-40))) {
    // Wider than an ulp: the window is decided only when the whole
    // enclosure [q - w, q + w] lies outside it, or (any-hit: no t to
    // round) inside it; rounding is monotone, so strict comparisons of the
    // rounded ends with T values hold for the exact ends.
    const double w = Y / (aD * (1 - 0x1p-30)) + std::abs(sdelta);
    if (double(q) + w < double(tlo) || double(q) - w > double(thi)) return Dist::out;
    if (!need_t && double(q) - w > double(tlo) && double(q) + w < double(thi)) return Dist::in;
    return Dist::undecided;
  }
  if (q < tlo || q > thi) return Dist::out;
  if (!(q > tlo && q < thi)) return Dist::undecided;  // on a window end (or a NaN window)
  if (need_t) t_out = q;
  return Dist::in;
}

// Stage 2b (exact.cpp), double inputs: t in double-word arithmetic where
// the long double enclosure was too wide to round; `in` only with t
// correctly rounded.
Dist t_double_word(const Ray<double>& r, const Vec3<double>& a, const Vec3<double>& b, const Vec3<double>& c,
                   double& t_out);

// The barycentrics from the certified Plücker values, clamped to [0, 1].
template <class C, class T>
[[gnu::always_inline]] inline TriangleHit<T> finish(T t, C U, C V, C W) {
  const C inv = C(1) / (U + V + W);
  const C b1 = std::min(std::max(V * inv, C(0)), C(1)), b2 = std::min(std::max(W * inv, C(0)), C(1));
  return TriangleHit<T>{t, T(b1), T(b2)};
}

// The compute type of stage 1b: double for float inputs, long double for double.
template <class T>
using TCompute = std::conditional_t<sizeof(T) == sizeof(float), double, long double>;

// The test after stage 1: sg, U, V, W and s are what signs<double> gave
// for these inputs (the scalar test below, or a lane of the 4-lane leaf,
// exact_simd.h, whose lanes compute them by the same operations: the same
// bits). need_t = false for any-hit (the verdict only). `pre`: the
// triangle's stage 1b terms if prepared (the same values edges() gives).
template <class T>
[[gnu::always_inline]] inline std::optional<TriangleHit<T>> after_signs(Signs sg, double U, double V, double W, int s,
                                                                        const Ray<T>& r, const Vec3<T>& a,
                                                                        const Vec3<T>& b, const Vec3<T>& c,
                                                                        const StoredEdges<TCompute<T>>* pre, bool cull,
                                                                        bool need_t) {
  constexpr bool kFloat = sizeof(T) == sizeof(float);
  using C = TCompute<T>;
  // Stage 1b from the prepared terms, or from the vertices.
  const auto stage1b = [&](bool want_t, T& t) __attribute__((always_inline)) {
    return pre ? enclose_t<C>(r, a, *pre, want_t, t) : enclose_t<C>(r, a, edges<C>(a, b, c), want_t, t);
  };
  // A culled back face is a miss too, tested in the same branch: with half
  // the rays from behind, two unpredictable branches in a row cost more
  // than the test itself.
  if ((sg == Signs::miss) | (cull & (sg == Signs::inside) & (s > 0))) return std::nullopt;
  if (sg == Signs::inside) {
    T t{};
    Dist ds = stage1b(need_t, t);
    if constexpr (!kFloat)
      if (ds == Dist::undecided) count_extended(), ds = t_double_word(r, a, b, c, t);
    if (ds == Dist::out) return std::nullopt;
    if (ds == Dist::in) return finish<double, T>(t, U, V, W);
    count_exact();
    return hit_exact(r, a, b, c, cull);
  }
  // Undecided signs (a ray through or near an edge or vertex): the plane's
  // t alone may put the crossing outside the window, whatever the signs
  // (a shadow ray leaving the surface, against the triangles around its
  // origin; a closest-hit ray behind its best hit).
  {
    T t{};
    if (stage1b(false, t) == Dist::out) return std::nullopt;
  }
  if constexpr (!kFloat) {
    count_extended();
    long double Ul, Vl, Wl;
    const Signs sl = signs<long double>(r, a, b, c, std::numeric_limits<long double>::infinity(), 0.0L, Ul, Vl, Wl, s);
    if (sl == Signs::miss) return std::nullopt;
    if (sl == Signs::inside) {
      if (cull && s > 0) return std::nullopt;
      T t{};
      Dist ds = stage1b(need_t, t);
      if (ds == Dist::undecided) ds = t_double_word(r, a, b, c, t);
      if (ds == Dist::out) return std::nullopt;
      if (ds == Dist::in) return finish<long double, T>(t, Ul, Vl, Wl);
    }
  }
  count_exact();
  return hit_exact(r, a, b, c, cull);
}

// Stage 1's range guard and underflow term (double inputs; float inputs in
// double need neither).
template <class T>
constexpr double kFilterLimit = sizeof(T) == sizeof(float) ? std::numeric_limits<double>::infinity() : 0x1p330;
template <class T>
constexpr double kFilterTau = sizeof(T) == sizeof(float) ? 0.0 : 0x1p-736;

// Culling from the prepared normal, before stage 1: det = n . d certainly
// positive is a back face, culled whatever U, V and W say (a crossing of
// the back, or a miss). In double from n rounded to double (its high part
// for double rays): n in the compute type is within 16 u PD of the exact
// det once dotted with d (stage 1b's bound, eD), rounding it to double and
// the dot's three roundings add at most 4 2^-53 sum_i |n_i| |d_i| <=
// 2^-51 PD (1 + 2^-50), so |D~ - det| < 2^-49 PD for both precisions;
// 2^-48 PD + 2^-1073 covers PD's own roundings and underflow (as stage
// 1b's eD), and a NaN (untamed edges) or infinite bound certifies nothing.
// About 15 operations against stage 1's 85: a back face costs a fifth.
template <class T, class E>
[[gnu::always_inline]] inline bool certainly_back(const Ray<T>& r, const E& e) {
  const double n0 = e.normal_double(0), n1 = e.normal_double(1), n2 = e.normal_double(2);
  const double dx = double(r.d.x), dy = double(r.d.y), dz = double(r.d.z);
  const double D = n0 * dx + n1 * dy + n2 * dz;
  const double PD = e.pn[0] * std::abs(dx) + e.pn[1] * std::abs(dy) + e.pn[2] * std::abs(dz);
  return D > 0x1p-48 * PD + 0x1p-1073;
}

// The whole test: stage 1, then the rest.
template <class T>
[[gnu::always_inline]] inline std::optional<TriangleHit<T>> test(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b,
                                                                 const Vec3<T>& c, const StoredEdges<TCompute<T>>* pre,
                                                                 bool cull, bool need_t) {
  if (cull && pre && certainly_back(r, *pre)) return std::nullopt;
  double U, V, W;
  int s = 0;
  const Signs sg = signs<double>(r, a, b, c, kFilterLimit<T>, kFilterTau<T>, U, V, W, s);
  return after_signs(sg, U, V, W, s, r, a, b, c, pre, cull, need_t);
}

// The prepared form: the vertices and the triangle's stage 1b terms.
template <class T>
struct Prepared {
  Vec3<T> a, b, c;
  StoredEdges<TCompute<T>> e;
};
template <class T>
Prepared<T> prepare(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  return {a, b, c, StoredEdges<TCompute<T>>::from(edges<TCompute<T>>(a, b, c))};
}

}  // namespace detail

template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return detail::test(r, a, b, c, nullptr, cull, true);
}

template <class T>
bool any(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, bool cull) {
  return detail::test(r, a, b, c, nullptr, cull, false).has_value();
}

// The same from the prepared form (bit for bit the same answers).
template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const detail::Prepared<T>& p, bool cull) {
  return detail::test(r, p.a, p.b, p.c, &p.e, cull, true);
}
template <class T>
bool any(const Ray<T>& r, const detail::Prepared<T>& p, bool cull) {
  return detail::test(r, p.a, p.b, p.c, &p.e, cull, false).has_value();
}

}  // namespace ra::exact
