// Möller & Trumbore (moller.h) on 4 triangles at once, for the BVH's leaves:
// the same operations in the same order per lane, so every lane's answer is
// bit-identical to moller::hit's (moller_simd_test.cpp checks it bit for bit).
//
// Why it is exact: IEEE 754 +, -, *, / are correctly rounded in SSE/AVX lanes
// as in scalar SSE, the expression trees below are moller::hit's (cross, dot
// and their left-to-right sums spelled out), and renderer/CMakeLists.txt
// compiles with -ffp-contract=off so no multiply-add is ever fused.
#pragma once
#include <immintrin.h>

#include <cstdint>

#include "../ray.h"

namespace ra::moller_simd {

// 32-byte vectors (4 doubles) pass only between always-inline helpers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// 4 triangles, structure of arrays: a[axis][lane] and the edges e1 = b - a,
// e2 = c - a rounded to T once here, which are the very values moller::hit
// computes from the same T vertices on every call. Unused lanes are all zero
// (det = 0: never a hit).
template <class T>
struct alignas(32) Tri4 {
  T a[3][4], e1[3][4], e2[3][4];
  void set(int lane, const Vec3<T>& va, const Vec3<T>& vb, const Vec3<T>& vc) {
    const Vec3<T> d1 = vb - va, d2 = vc - va;
    for (int k = 0; k < 3; ++k) {
      a[k][lane] = va[k];
      e1[k][lane] = d1[k];
      e2[k][lane] = d2[k];
    }
  }
};

template <class T>
struct Lanes;
template <>
struct Lanes<float> {
  typedef float V __attribute__((vector_size(16)));
  typedef std::int32_t M __attribute__((vector_size(16)));
};
template <>
struct Lanes<double> {
  typedef double V __attribute__((vector_size(32)));
  typedef std::int64_t M __attribute__((vector_size(32)));
};

// The 4 lanes' t, b1, b2; bit i of `hits` set when lane i is a hit.
template <class T>
struct Hit4 {
  T t[4], b1[4], b2[4];
  int hits = 0;
};

template <class T>
[[gnu::always_inline]] inline typename Lanes<T>::V load(const T* p) {
  typename Lanes<T>::V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

// x in every lane, bit for bit (V{} + x would add +0: a -0 would become +0),
// as a shuffle of lane 0: one vbroadcastsd/ss on AVX2 (GCC builds V{x, x,
// x, x} of doubles from a vmovddup and a vinsertf128).
template <class T>
[[gnu::always_inline]] inline typename Lanes<T>::V bcast(T x) {
  typedef T V2 __attribute__((vector_size(2 * sizeof(T))));
  const V2 v{x, x};
  return __builtin_shufflevector(v, v, 0, 0, 0, 0);
}

// The ray in every lane, made once per ray by the caller rather than per
// leaf: GCC spends 3 instructions on each broadcast from a register
// (vmovddup, vmovapd, vbroadcastsd), 24 of a leaf test's 110.
template <class T>
struct RayLanes {
  typename Lanes<T>::V ox, oy, oz, dx, dy, dz, tmin;
};
template <class T>
[[gnu::always_inline]] inline RayLanes<T> ray_lanes(const Ray<T>& r) {
  return {bcast(r.o.x), bcast(r.o.y), bcast(r.o.z), bcast(r.d.x), bcast(r.d.y), bcast(r.d.z), bcast(r.tmin)};
}

// Bit i set: lane i of m is true. kAvx (the caller is compiled for AVX2):
// one vmovmskpd for 4 doubles; GCC turns the lane-by-lane form into 15
// instructions and two branches.
template <bool kAvx, class M>
[[gnu::always_inline]] inline int mask_bits(M m) {
#if !defined(__clang__)
  if constexpr (kAvx && sizeof(M) == 32) {
    int r;
    asm("vmovmskpd %1, %0" : "=r"(r) : "x"(m));
    return r;
  }
#endif
  // 4 floats: one movmskps, baseline SSE.
  if constexpr (sizeof(M) == 16) return _mm_movemask_ps((__m128)m);
  int bits = 0;
  for (int i = 0; i < 4; ++i) bits |= m[i] ? 1 << i : 0;
  return bits;
}

template <bool kAvx = false, class T>
[[gnu::always_inline]] inline void hit4(const RayLanes<T>& r, T tmax, const Tri4<T>& tri, bool cull, Hit4<T>& out) {
  using V = typename Lanes<T>::V;
  using M = typename Lanes<T>::M;
  const V dx = r.dx, dy = r.dy, dz = r.dz;
  const V ax = load(tri.a[0]), ay = load(tri.a[1]), az = load(tri.a[2]);
  const V e1x = load(tri.e1[0]), e1y = load(tri.e1[1]), e1z = load(tri.e1[2]);
  const V e2x = load(tri.e2[0]), e2y = load(tri.e2[1]), e2z = load(tri.e2[2]);
  // p = cross(d, e2)
  const V px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
  const V det = e1x * px + e1y * py + e1z * pz;
  M ok = cull ? (det > V{}) : (det != V{});
  const V inv = T(1) / det;
  // s = o - a
  const V sx = r.ox - ax, sy = r.oy - ay, sz = r.oz - az;
  const V u = (sx * px + sy * py + sz * pz) * inv;
  ok &= (u >= V{}) & (u <= V{} + T(1));
  // No early exit where every lane has failed by here (most leaf tests):
  // whether one does is data-dependent, and the mispredicted branch cost
  // more than the rest of the test (without it: shadow rays 5-6% faster,
  // primary 2-4%, against Embree on the bunny and the dragon).
  // q = cross(s, e1)
  const V qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  const V v = (dx * qx + dy * qy + dz * qz) * inv;
  ok &= (v >= V{}) & (u + v <= V{} + T(1));
  const V t = (e2x * qx + e2y * qy + e2z * qz) * inv;
  ok &= (t >= r.tmin) & (t <= bcast(tmax));
  const int hits = mask_bits<kAvx>(ok);
  out.hits = hits;
  if (!hits) return;
  __builtin_memcpy(out.t, &t, sizeof t);
  __builtin_memcpy(out.b1, &u, sizeof u);
  __builtin_memcpy(out.b2, &v, sizeof v);
}
template <class T>
[[gnu::always_inline]] inline void hit4(const Ray<T>& r, const Tri4<T>& tri, bool cull, Hit4<T>& out) {
  hit4(ray_lanes(r), r.tmax, tri, cull, out);
}

#pragma GCC diagnostic pop

}  // namespace ra::moller_simd
