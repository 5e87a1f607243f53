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
// after_signs, which is what the scalar test runs next. Nothing else is
// decided here.
#pragma once
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
  V4 ox, oy, oz, dx, dy, dz, ksd, limit, tau;
  bool sd_ok;
};
template <class T>
[[gnu::always_inline]] inline RayLanes ray_lanes(const Ray<T>& r) {
  using moller_simd::bcast;
  const double dx = double(r.d.x), dy = double(r.d.y), dz = double(r.d.z);
  const double sd = std::abs(dx) + std::abs(dy) + std::abs(dz);
  constexpr double k = 16.0 * exact::detail::unit_roundoff<double>();
  constexpr double limit = exact::detail::kFilterLimit<T>, tau = exact::detail::kFilterTau<T>;
  return {bcast(double(r.o.x)), bcast(double(r.o.y)), bcast(double(r.o.z)), bcast(dx),  bcast(dy), bcast(dz),
          bcast(k * sd),        bcast(limit),         bcast(tau),           sd <= limit};
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
// s = +1 / -1). A live lane in neither is undecided.
struct Signs4 {
  double U[4], V[4], W[4];
  int miss, pos, neg;
};
template <bool kAvx = false, class T>
[[gnu::always_inline]] inline void signs4(const RayLanes& r, const Tri4<T>& tri, Signs4& out) {
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
}

// The leaf: f(lane, exact::detail::Signs, U, V, W, s) for each of the
// `live` lanes (bit i: lane i) that stage 1 did not reject; the caller
// finishes each with after_signs on the lane's triangle.
template <bool kAvx = false, class T, class F>
[[gnu::always_inline]] inline void leaf4(const RayLanes& r, const Tri4<T>& tri, int live, F&& f) {
  Signs4 s;
  signs4<kAvx>(r, tri, s);
  using exact::detail::Signs;
  for (int rest = live & ~s.miss; rest; rest &= rest - 1) {
    const int l = __builtin_ctz(unsigned(rest));
    const int bit = 1 << l;
    const Signs sg = (s.pos | s.neg) & bit ? Signs::inside : Signs::undecided;
    if (f(l, sg, s.U[l], s.V[l], s.W[l], s.pos & bit ? 1 : s.neg & bit ? -1 : 0)) return;
  }
}

#pragma GCC diagnostic pop

}  // namespace ra::exact_simd
