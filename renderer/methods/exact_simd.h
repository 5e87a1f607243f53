// exact (exact.h) on 4 triangles at once, for the BVH's leaves: stage 1
// (the double filter, `exact::detail::signs<double>`) in 4 double lanes,
// the rest per lane by the scalar code (`exact::detail::after_signs`), so
// every answer is the scalar kernel's, bit for bit (exact_simd_test.cpp
// checks hits, t, b1, b2 and the filter's values themselves).
//
// Why it is exact. A lane computes U, V, W, |d|_1, max |P'| and the bounds
// by the very expression trees of signs<double> (translations, crosses and
// dots spelled out the same, left-to-right sums, std::max's (x < y ? y : x)
// with its NaN behaviour, fabs as the sign bit cleared): IEEE 754 +, -, *
// are correctly rounded in AVX/SSE lanes as in scalar SSE, float -> double
// conversion is exact either way, and renderer/CMakeLists.txt compiles with
// -ffp-contract=off, so no multiply-add is fused (the tracer's AVX2+FMA
// entry points included). So each lane's U, V, W and verdict (miss,
// inside with its sign, undecided) are the scalar filter's; a lane the
// filter rejects (two certified opposite signs) is the scalar kernel's
// miss, and every other lane is handed, with its U, V, W and verdict, to
// after_signs, which is what the scalar test runs next. The one other
// decision made here is a miss that exact arithmetic makes too (the plane
// crossed outside the window, by bounds proven beside signs4): the scalar
// kernel's verdicts are exact, so it answers the same miss.
#pragma once
#include <algorithm>
#include <cstdint>

#include "exact.h"
#include "moller_simd.h"

namespace ra::exact_simd {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

typedef double V4 __attribute__((vector_size(32)));
typedef std::int64_t M4 __attribute__((vector_size(32)));

// 4 triangles' vertices in T, structure of arrays: v[3 * vertex + axis][lane]
// (vertex 0, 1, 2 = a, b, c). Unused lanes are zeros and never looked at:
// the leaf's count says which lanes are live.
template <class T>
struct alignas(4 * sizeof(T)) Tri4 {
  T v[9][4];
  void set(int lane, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
    for (int k = 0; k < 3; ++k) {
      v[k][lane] = a[k];
      v[3 + k][lane] = b[k];
      v[6 + k][lane] = c[k];
    }
  }
};

// The ray in every lane, in double (stage 1's compute type for both
// precisions), and its lane-independent terms computed as signs<double>
// computes them: sd = |d_x| + |d_y| + |d_z|, ksd = 2^-49 sd, and the range
// guard's half on sd (sd <= limit, false for NaN).
struct RayLanes {
  V4 ox, oy, oz, dx, dy, dz, ksd, limit, tau, tlo;
  bool sd_ok;
};
template <class T>
[[gnu::always_inline]] inline RayLanes ray_lanes(const Ray<T>& r) {
  using moller_simd::bcast;
  const double dx = double(r.d.x), dy = double(r.d.y), dz = double(r.d.z);
  const double sd = std::abs(dx) + std::abs(dy) + std::abs(dz);
  constexpr double k = 16.0 * exact::detail::unit_roundoff<double>();
  constexpr double limit = exact::detail::kFilterLimit<T>, tau = exact::detail::kFilterTau<T>;
  const double tlo = double(std::max(r.tmin, T(0)));
  return {bcast(double(r.o.x)), bcast(double(r.o.y)), bcast(double(r.o.z)), bcast(dx),  bcast(dy),  bcast(dz),
          bcast(k * sd),        bcast(limit),         bcast(tau),           bcast(tlo), sd <= limit};
}

[[gnu::always_inline]] inline V4 vabs(V4 x) {
  const M4 sign = {INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN};
  return (V4)((M4)x & ~sign);
}
// std::max(x, y) lane by lane: (x < y) ? y : x (a NaN y gives x, a NaN x gives x).
[[gnu::always_inline]] inline V4 vmax(V4 x, V4 y) { return x < y ? y : x; }
[[gnu::always_inline]] inline V4 vmax3(V4 x, V4 y, V4 z) { return vmax(x, vmax(y, z)); }

template <class T>
[[gnu::always_inline]] inline V4 load(const T* p) {
  if constexpr (sizeof(T) == sizeof(double)) {
    return moller_simd::load(p);
  } else {
    return __builtin_convertvector(moller_simd::load(p), V4);
  }
}

// Stage 1 of 4 lanes: U, V, W per lane and, as bit masks over the lanes,
// `miss` (rejected: the scalar kernel's miss), `pos` / `neg` (inside with
// s = +1 / -1). A live lane in neither is undecided. Then, for the live
// lanes stage 1 did not reject (when there are any), `out`: the plane is
// certainly crossed outside the window [tlo, thi] (below), so exact
// arithmetic, and with it the scalar kernel, answers a miss.
//
// The window test. N = A' . (B' x C') = n . A' (the header's triple
// product; its cross product is U's, so it costs three products and two
// sums) and det = U + V + W = n . d; t = N / det. N~ passes through 8
// roundings per term (one more than U's: A' is rounded too), so, as for U,
// |N~ - N| <= gamma(8) 2 |A'|_1 max|B'| max|C'| (1 + 13u) < 2^-48 s_a m_b
// m_c (+ tau for double inputs, as U's: the factor after the cross product
// is |a'_i| <= 2^330); det~ = fl(fl(U~ + V~) + W~) is within eU + eV + eW +
// 2u (1 + u)(|U~| + |V~| + |W~|) of det, taken with 2^-51 and the factor
// 1 + 2^-40 (its own roundings). With both bounds: t < 0 <= tlo where N and
// det are certainly of opposite signs; |t| <= (|N~| + eN) / (|det~| -
// eDet) < tlo; t >= (|N~| - eN) / (|det~| + eDet) > thi where they are
// certainly of one sign. The products and sums of those comparisons are of
// nonnegative values (at most 4 roundings a side), covered by the factors
// 1 -+ 2^-40. Lanes outside the range guard are never `out`.
struct Signs4 {
  double U[4], V[4], W[4];
  int miss, pos, neg, out;
};
template <bool kAvx = false, class T>
[[gnu::always_inline]] inline void signs4(const RayLanes& r, double thi, const Tri4<T>& tri, int live, Signs4& out) {
  const V4 dx = r.dx, dy = r.dy, dz = r.dz;
  const V4 ax = load(tri.v[0]) - r.ox, ay = load(tri.v[1]) - r.oy, az = load(tri.v[2]) - r.oz;
  const V4 bx = load(tri.v[3]) - r.ox, by = load(tri.v[4]) - r.oy, bz = load(tri.v[5]) - r.oz;
  const V4 cx = load(tri.v[6]) - r.ox, cy = load(tri.v[7]) - r.oy, cz = load(tri.v[8]) - r.oz;
  // U = d . (B' x C'), V = d . (C' x A'), W = d . (A' x B'): signs<double>'s trees.
  const V4 U = dx * (by * cz - bz * cy) + dy * (bz * cx - bx * cz) + dz * (bx * cy - by * cx);
  const V4 V = dx * (cy * az - cz * ay) + dy * (cz * ax - cx * az) + dz * (cx * ay - cy * ax);
  const V4 W = dx * (ay * bz - az * by) + dy * (az * bx - ax * bz) + dz * (ax * by - ay * bx);
  const V4 ma = vmax3(vabs(ax), vabs(ay), vabs(az));
  const V4 mb = vmax3(vabs(bx), vabs(by), vabs(bz));
  const V4 mc = vmax3(vabs(cx), vabs(cy), vabs(cz));
  const M4 guard = vmax3(ma, mb, mc) <= r.limit;  // and sd <= limit: the caller's
  const V4 eU = r.ksd * mb * mc + r.tau, eV = r.ksd * mc * ma + r.tau, eW = r.ksd * ma * mb + r.tau;
  const M4 pu = U > eU, nu = U<-eU, pv = V> eV, nv = V<-eV, pw = W> eW, nw = W < -eW;
  const M4 miss = guard & (pu | pv | pw) & (nu | nv | nw);
  const M4 pos = guard & ~miss & pu & pv & pw;
  const M4 neg = guard & ~miss & ~pos & nu & nv & nw;
  const int ok = r.sd_ok ? -1 : 0;
  out.miss = moller_simd::mask_bits<kAvx>(miss) & ok;
  out.pos = moller_simd::mask_bits<kAvx>(pos) & ok;
  out.neg = moller_simd::mask_bits<kAvx>(neg) & ok;
  __builtin_memcpy(out.U, &U, sizeof U);
  __builtin_memcpy(out.V, &V, sizeof V);
  __builtin_memcpy(out.W, &W, sizeof W);
  out.out = 0;
  if (const int cand = live & ~out.miss & ok) {
    using moller_simd::bcast;
    const V4 N = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx);
    const V4 eN = bcast(0x1p-48) * (vabs(ax) + vabs(ay) + vabs(az)) * mb * mc + r.tau;
    const V4 det = U + V + W;
    const V4 eDet = (eU + eV + eW + bcast(0x1p-51) * (vabs(U) + vabs(V) + vabs(W))) * bcast(1 + 0x1p-40);
    const V4 aN = vabs(N), aDet = vabs(det), up = bcast(1 + 0x1p-40), down = bcast(1 - 0x1p-40);
    const M4 np = N > eN, nn = N<-eN, dp = det> eDet, dn = det < -eDet;
    const M4 behind = (np & dn) | (nn & dp);
    const M4 near = (dp | dn) & ((aN + eN) * up < (aDet - eDet) * r.tlo * down);
    const M4 beyond = ((np & dp) | (nn & dn)) & ((aN - eN) * down > (aDet + eDet) * bcast(thi) * up);
    out.out = moller_simd::mask_bits<kAvx>(guard & (behind | near | beyond)) & cand;
  }
}

// The leaf: f(lane, exact::detail::Signs, U, V, W, s) for each of the
// `live` lanes (bit i: lane i) that neither stage 1 nor the window test
// rejected; the caller finishes each with after_signs on the lane's
// triangle. thi: the window's current end.
template <bool kAvx = false, class T, class F>
[[gnu::always_inline]] inline void leaf4(const RayLanes& r, T thi, const Tri4<T>& tri, int live, F&& f) {
  Signs4 s;
  signs4<kAvx>(r, double(thi), tri, live, s);
  using exact::detail::Signs;
  for (int rest = live & ~s.miss & ~s.out; rest; rest &= rest - 1) {
    const int l = __builtin_ctz(unsigned(rest));
    const int bit = 1 << l;
    const Signs sg = (s.pos | s.neg) & bit ? Signs::inside : Signs::undecided;
    if (f(l, sg, s.U[l], s.V[l], s.W[l], s.pos & bit ? 1 : s.neg & bit ? -1 : 0)) return;
  }
}

#pragma GCC diagnostic pop

}  // namespace ra::exact_simd
