// An 8-wide bounding volume hierarchy over one mesh's triangles, the modern
// reference next to document 002's optimisations (backface culling, the
// bounding sphere in bounding_sphere.h). Sources: binned SAH (Wald 2007, "On
// fast construction of SAH-based BVHs"), 8 children per node (Dammertz et
// al. 2008, "Shallow bounding volume hierarchies"; built directly as
// Embree's BVH8 builder does: the child with the largest box split next; on
// all threads, the tree the same for every thread count; bvh.cpp), and
// boxes tested 8 at a time in float with the rounding made conservative
// (Ize 2013, "Robust BVH Ray Traversal"; Embree's robust mode).
//
// Guarantee: every leaf whose padded box the exact ray segment [tmin, tmax]
// meets is visited, so a hit the triangle kernel reports (inside its triangle
// up to the kernel's rounding, which the padding covers) is never missed.
// Visit order never matters for the answer: the tracer breaks ties on t by
// object and triangle index, so the closest hit is the same as a loop over
// all triangles (the --accel identity tests).
//
// Why the float test is conservative for double (or float) rays:
//  - boxes are rounded outward to float and padded by `pad` (the tracer uses
//    1e-5 of the mesh's size and distance from the origin);
//  - the ray origin is rounded to float. Where |o_a| <= 2 * size the error is
//    <= 2^-24 * 2 size, far below the padding; farther out every box plane
//    is at least |o_a| / 2 away, so the error is at most 2^-23 relative to
//    (plane - o_a), i.e. relative in t;
//  - d rounded to float (double rays), 1/d in float, the subtraction and
//    the product add 4 roundings (the fused test of meet8_fma: 3, plus an
//    absolute term bounded per ray):
//    all of it is relative to t, covered by widening [tnear, tfar] by
//    kRelSlack = 2^-20 (16 float ulps) of their magnitudes;
//  - d_a = 0 gives 1/d_a = +-inf: (plane - o_a) * inf is +-inf, or NaN when
//    o_a lies exactly on the plane, which the min/max below ignore (the slab
//    then constrains nothing), as Williams et al. 2005 intend;
//  - a ray float cannot hold (|o| > 1e30, |d| or |1/d| outside float's
//    normal range while d != 0) visits every leaf instead.
#pragma once
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <type_traits>
#include <vector>

#include "../vec.h"

namespace ra {

// Eight children's boxes, structure of arrays: lo[axis][child]. 256 bytes
// (224 used), four cache lines, aligned.
struct alignas(64) BvhNode {
  float lo[3][8];
  float hi[3][8];
  std::uint32_t child[8];  // Bvh::kEmpty, a leaf (Bvh::kLeaf | ...) or a node index
};

struct Bvh {
  static constexpr int kWidth = 8;  // children per node
  static constexpr int kBins = 16;
  static constexpr int kMaxLeaf = 4;     // triangles per leaf; every leaf owns 4 slots
  static constexpr int kMaxDepth = 128;  // binary depth bound (build); 8-wide depth is below it
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  static constexpr std::uint32_t kLeaf = 0x80000000u;        // child word: leaf flag
  static constexpr std::uint32_t kNoTriangle = 0xFFFFFFFFu;  // order[] of an unused slot
  static constexpr float kRelSlack = 1.0f / (1 << 20);

  std::vector<BvhNode> nodes;        // nodes[0] is the root (empty for an empty mesh)
  std::vector<std::uint32_t> order;  // slot -> triangle; leaf k's slots are 4k .. 4k + count - 1
  // A hint for the traversal, not part of the tree (build leaves it false):
  // ask for the nodes and leaves either side in memory of every one asked
  // for (prefetch_node says why). The owner of the leaves sets it
  // (render.cpp: where the nodes and leaves outgrow the last-level cache).
  bool prefetch_neighbours = false;

  static bool is_leaf(std::uint32_t c) { return c != kEmpty && (c & kLeaf); }
  // A leaf's first slot (a multiple of 4) and its number of triangles (1..4).
  static std::uint32_t leaf_first(std::uint32_t c) { return (c & 0x1FFFFFFFu) << 2; }
  static std::uint32_t leaf_count(std::uint32_t c) { return ((c >> 29) & 3u) + 1; }
  static std::uint32_t make_leaf(std::uint32_t leaf_index, std::uint32_t count) {
    return kLeaf | ((count - 1) << 29) | leaf_index;
  }

  // Builds over triangles given by their boxes; `pad` widens every box.
  // Uses up to `threads` threads (0: all cores); the tree (nodes and order,
  // byte for byte) depends neither on the thread count nor on `simd` (false:
  // the baseline x86-64 build even where the CPU has AVX2).
  static Bvh build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad, int threads = 0,
                   bool simd = true);
  // The same with triangles [begin, end)'s boxes written by `boxes` to
  // lo[0 .. end - begin) and hi[...] on the build's threads, a piece at a
  // time (no array of all the boxes).
  using BoxFn = std::function<void(std::size_t begin, std::size_t end, Vec3d* lo, Vec3d* hi)>;
  static Bvh build(std::size_t n, const BoxFn& boxes, double pad, int threads = 0, bool simd = true);
};

namespace bvh_detail {

// 32-byte vectors are passed only between always-inline helpers, so the
// ABI note (how they would be passed without AVX) does not apply.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// 8 lanes: one AVX register where the caller is compiled for AVX2 (the
// tracer's AVX2 entry points), two SSE registers otherwise.
typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));

[[gnu::always_inline]] inline v8f load8(const float* p) {
  v8f v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
// A broadcast (v8f{} + x would add +0 to every lane: not foldable, -0 + 0 = +0),
// written as a shuffle of lane 0: one vbroadcastss (GCC builds v8f{x, ...}
// from 4 vinsertps and a vperm2f128).
typedef float v4f __attribute__((vector_size(16)));
[[gnu::always_inline]] inline v8f splat(float x) {
  const v4f v{x, x, x, x};
  return __builtin_shufflevector(v, v, 0, 0, 0, 0, 0, 0, 0, 0);
}
[[gnu::always_inline]] inline v8f vabs(v8f x) { return (v8f)((v8i)x & 0x7FFFFFFF); }
[[gnu::always_inline]] inline int movemask(v8i m) {
  __m128 lo, hi;
  __builtin_memcpy(&lo, &m, 16);
  __builtin_memcpy(&hi, reinterpret_cast<const char*>(&m) + 16, 16);
  return _mm_movemask_ps(lo) | _mm_movemask_ps(hi) << 4;
}

// float rounded towards -inf / +inf from double.
// A step of a relative 2^-23 (at least one ulp for normal floats) instead
// of nextafter's call; below 1e-30 in magnitude, an absolute 1e-30 step,
// far more than the half ulp float(x) can be off there.
inline float round_down(double x) {
  const float f = float(x);
  if (!(double(f) > x)) return f;
  return f > 1e-30f ? f * (1 - 0x1p-23f) : f < -1e-30f ? f * (1 + 0x1p-23f) : f - 1e-30f;
}
inline float round_up(double x) {
  const float f = float(x);
  if (!(double(f) < x)) return f;
  return f > 1e-30f ? f * (1 + 0x1p-23f) : f < -1e-30f ? f * (1 - 0x1p-23f) : f + 1e-30f;
}
// A float >= x (for the traversal's tmax), without round_up's branches
// (whether float(x) fell below x is a coin toss per ray: the mispredicted
// branch cost about 2% of a shadow ray). float(x) plus |f| 2^-23 (1 to 2
// ulps, exact, so the sum rounds to at least the next float up) plus
// 1e-30 (the step below 1e-30, as in round_up): always above x, by up to
// 2 ulps more than round_up, which only widens the window the boxes are
// tested against. +inf stays +inf; -inf and NaN give NaN (an empty window:
// no box passes, as no hit can).
inline float above(double x) {
  const float f = float(x);
  return f + (std::fabs(f) * 0x1p-23f + 1e-30f);
}

// Byte offsets in BvhNode of each axis's near and far planes, by the signs
// of the three 1/d_a (bit a set: 1/d_a < 0 or -0, and hi is the near plane):
// kPlanes[signs][0..2] near, [3..5] far. A row of a table instead of six
// values made per ray (they are read from memory in the loop either way).
constexpr unsigned plane_offset(int signs, int a, bool near) {
  return unsigned(((((signs >> a) & 1) != 0) == near ? offsetof(BvhNode, hi) : offsetof(BvhNode, lo)) + 32 * a);
}
#define RA_PLANES(s)                                                                                         \
  {                                                                                                          \
    plane_offset(s, 0, true), plane_offset(s, 1, true), plane_offset(s, 2, true), plane_offset(s, 0, false), \
        plane_offset(s, 1, false), plane_offset(s, 2, false)                                                 \
  }
inline constexpr unsigned kPlanes[8][6] = {RA_PLANES(0), RA_PLANES(1), RA_PLANES(2), RA_PLANES(3),
                                           RA_PLANES(4), RA_PLANES(5), RA_PLANES(6), RA_PLANES(7)};
#undef RA_PLANES

// The ray as the box test sees it: scalars, broadcast where used (a
// broadcast from memory costs a load; eleven 8-lane copies per ray cost
// more than the boxes a missing ray tests).
struct BoxRay {
  v4f o, inv;              // lanes x, y, z (and 0, 1)
  const unsigned* planes;  // kPlanes row: near_off[3], far_off[3]
  float tmin;
  bool exact = true;  // false: float cannot hold this ray; visit every leaf
  // tmin >= 0 (every ray the tracer casts): then tnear >= 0, and tfar may
  // carry all the slack (Ize 2013's one-sided test, 2 operations fewer).
  bool nonneg = false;
  // The fused form (meet8_fma): oi = o * inv rounded to float, and
  // abs_slack = 3 E with E above its rounding error (see meet8_fma). Usable
  // when exact, nonneg, and every inv and oi finite (no d_a = 0).
  bool fma_ok = false;
  v4f oi;
  float abs_slack;
};

// One float division for the three 1/d_a, of d rounded to float (for double
// rays one rounding more than the correctly rounded 1/d: 2 of the 16 ulps
// of kRelSlack; a double division is slower, on every ray's critical path).
template <class T>
[[gnu::always_inline]] inline BoxRay box_ray(const Vec3<T>& o, const Vec3<T>& d, T tmin) {
  typedef float v4 __attribute__((vector_size(16)));
  typedef int v4m __attribute__((vector_size(16)));
  const v4 df{float(d.x), float(d.y), float(d.z), 1};
  const v4 inv = v4{1, 1, 1, 1} / df;
  const v4 of{float(o.x), float(o.y), float(o.z), 0};
  // Bit a set: d_a is exactly zero (either sign), tested on T's bits (a
  // compare would cost a NaN-safe sequence of 6 instructions per axis).
  auto zero = [](T x) __attribute__((always_inline)) {
    if constexpr (sizeof(T) == 8)
      return (std::bit_cast<std::uint64_t>(x) << 1) == 0;
    else
      return (std::bit_cast<std::uint32_t>(x) << 1) == 0;
  };
  const int dz = int(zero(d.x)) | int(zero(d.y)) << 1 | int(zero(d.z)) << 2;
  const v4 abs_d = (v4)((v4m)df & 0x7FFFFFFF), abs_inv = (v4)((v4m)inv & 0x7FFFFFFF),
           abs_o = (v4)((v4m)of & 0x7FFFFFFF);
  const v4 oi = of * inv, abs_oi = (v4)((v4m)oi & 0x7FFFFFFF);
  // Float must hold the origin, and d_a and 1/d_a must be normal floats
  // unless d_a = 0 (d_a's rounding to float must be relative).
  constexpr float kMin = std::numeric_limits<float>::min();
  const v4m normal_m = (abs_d >= kMin) & (abs_inv >= kMin) & (abs_inv <= std::numeric_limits<float>::max());
  const int normal = _mm_movemask_ps((__m128)normal_m);
  const int held = _mm_movemask_ps((__m128)(abs_o <= 1e30f));
  const int fused = normal & _mm_movemask_ps((__m128)(abs_oi <= std::numeric_limits<float>::max()));
  BoxRay b;
  b.o = of;
  b.inv = inv;
  b.oi = oi;
  b.exact = (held & (dz | normal) & 7) == 7;
  b.planes = kPlanes[_mm_movemask_ps((__m128)inv) & 7];
  b.tmin = round_down(double(tmin));
  b.nonneg = b.tmin >= 0;
  b.fma_ok = b.exact && b.nonneg && (fused & 7) == 7;
  // E = 2^-22 max_a |oi_a| + 2^-126 bounds each |o_a inv_a - oi_a| (at most
  // half an ulp of oi_a, 2^-24 |oi_a|, or 2^-150 where oi_a is subnormal).
  const float m = std::max(std::max(abs_oi[0], abs_oi[1]), abs_oi[2]);
  b.abs_slack = 3 * (m * 0x1p-22f + 0x1p-126f);
  return b;
}

// The box ray's values in 8 lanes, made once per ray by the traversal
// (kept in registers or one load each through the loop).
struct BoxRay8 {
  v8f o[3], inv[3], oi[3], tmin, abs_slack;
  const unsigned* planes;  // kPlanes row: near_off[3], far_off[3]
  bool nonneg;
};
[[gnu::always_inline]] inline BoxRay8 widen(const BoxRay& r) {
  BoxRay8 w;
  // Lane a to all 8 lanes: one shuffle (vbroadcastss / vpermps) each.
  w.o[0] = __builtin_shufflevector(r.o, r.o, 0, 0, 0, 0, 0, 0, 0, 0);
  w.o[1] = __builtin_shufflevector(r.o, r.o, 1, 1, 1, 1, 1, 1, 1, 1);
  w.o[2] = __builtin_shufflevector(r.o, r.o, 2, 2, 2, 2, 2, 2, 2, 2);
  w.inv[0] = __builtin_shufflevector(r.inv, r.inv, 0, 0, 0, 0, 0, 0, 0, 0);
  w.inv[1] = __builtin_shufflevector(r.inv, r.inv, 1, 1, 1, 1, 1, 1, 1, 1);
  w.inv[2] = __builtin_shufflevector(r.inv, r.inv, 2, 2, 2, 2, 2, 2, 2, 2);
  w.oi[0] = __builtin_shufflevector(r.oi, r.oi, 0, 0, 0, 0, 0, 0, 0, 0);
  w.oi[1] = __builtin_shufflevector(r.oi, r.oi, 1, 1, 1, 1, 1, 1, 1, 1);
  w.oi[2] = __builtin_shufflevector(r.oi, r.oi, 2, 2, 2, 2, 2, 2, 2, 2);
  w.planes = r.planes;
  w.tmin = splat(r.tmin);
  w.abs_slack = splat(r.abs_slack);
  w.nonneg = r.nonneg;
  return w;
}

// Bit i set: child i's box meets [tmin, tmax]; tnear gets each box's
// lower bound of the entry t (for ordering and pruning).
[[gnu::always_inline]] inline int meet8(const BvhNode& n, const BoxRay8& r, float tmax, v8f& tnear) {
  v8f tn = r.tmin, tf = splat(tmax);
  for (int a = 0; a < 3; ++a) {
    const char* base = reinterpret_cast<const char*>(&n);
    const v8f nearp = load8(reinterpret_cast<const float*>(base + r.planes[a]));
    const v8f farp = load8(reinterpret_cast<const float*>(base + r.planes[3 + a]));
    const v8f t0 = (nearp - r.o[a]) * r.inv[a];
    const v8f t1 = (farp - r.o[a]) * r.inv[a];
    // NaN (origin exactly on the plane of a d_a = 0 slab) keeps the old bound.
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
  }
  if (r.nonneg) {
    // tn >= 0, so a hit needs tf >= 0 too: true tnear >= tn (1 - s) and true
    // tfar <= tf (1 + s), and tn (1 - s) <= tf (1 + s) is within
    // tn <= tf (1 + 4 s). tnear is not lowered: callers prune against
    // tmax (1 + 4 s) (traverse's `prune`).
    tnear = tn;
    return movemask(tn <= tf * splat(1 + 4 * Bvh::kRelSlack));
  }
  // The slack is capped at FLT_MAX: an entry or exit t that overflowed to
  // +-inf stays infinite instead of becoming inf - inf = NaN (the kernel
  // can report a hit at t = inf in float when the true t overflows).
  const v8f slack = splat(Bvh::kRelSlack), cap = splat(std::numeric_limits<float>::max());
  const v8f sn = vabs(tn) * slack, sf = vabs(tf) * slack;
  tnear = tn - (sn < cap ? sn : cap);
  const v8f far_up = tf + (sf < cap ? sf : cap);
  return movemask(tnear <= far_up);
}

// a * b - c and a * b + c rounded once, and the sign bits of 8 lanes: one
// AVX2/FMA instruction each. Written as assembly because the traversal is
// generic code inlined into the tracer's AVX2+FMA entry points (GCC does
// not inline target-specific intrinsics into it); only those entry points
// instantiate them (traverse's kFma). Operands "v": any of the 32 vector
// registers where the caller is compiled for AVX-512 ("x", the first 16
// only, made GCC copy the ray's values into them: 7 moves a node);
// vmovmskps has no AVX-512 encoding and keeps "x".
#if defined(__clang__)
// clang accepts a 32-byte "x" operand only in functions compiled for AVX,
// and this generic code is not. Lane by lane, the same values: fmaf rounds
// a * b - c once, as vfmsub213ps does (clang builds only the fuzz targets).
[[gnu::always_inline]] inline v8f fmsub(v8f a, v8f b, v8f c) {
  for (int i = 0; i < 8; ++i) a[i] = std::fmaf(a[i], b[i], -c[i]);
  return a;
}
[[gnu::always_inline]] inline v8f fmadd(v8f a, v8f b, v8f c) {
  for (int i = 0; i < 8; ++i) a[i] = std::fmaf(a[i], b[i], c[i]);
  return a;
}
[[gnu::always_inline]] inline float lane_avx(v8f v, int i) { return v[i]; }
[[gnu::always_inline]] inline int movemask_avx(v8i m) {
  int r = 0;
  for (int i = 0; i < 8; ++i) r |= (m[i] < 0 ? 1 : 0) << i;
  return r;
}
#else
[[gnu::always_inline]] inline v8f fmsub(v8f a, v8f b, v8f c) {
  asm("vfmsub213ps %2, %1, %0" : "+v"(a) : "v"(b), "vm"(c));
  return a;
}
[[gnu::always_inline]] inline v8f fmadd(v8f a, v8f b, v8f c) {
  asm("vfmadd213ps %2, %1, %0" : "+v"(a) : "v"(b), "vm"(c));
  return a;
}
// Lane i of v, without a trip through memory (storing v and loading a
// lane stalls: the 4-byte load cannot take its bytes from the 32-byte store
// in flight).
[[gnu::always_inline]] inline float lane_avx(v8f v, int i) {
  const v8i idx{i, i, i, i, i, i, i, i};
  v8f r;
  asm("vpermps %1, %2, %0" : "=v"(r) : "v"(v), "v"(idx));
  return r[0];
}
[[gnu::always_inline]] inline int movemask_avx(v8i m) {
  int r;
  asm("vmovmskps %1, %0" : "=r"(r) : "x"(m));
  return r;
}
#endif

// meet8 with one fused multiply-subtract per plane, t = p inv - oi, for
// rays with fma_ok (Embree's form; here made conservative). Against
// meet8's fl(fl(p - o) inv) it rounds once where meet8 rounds twice, and
// adds the absolute error d_a = o_a inv_a - oi_a (|d_a| <= E / 4):
// t' = ((p - o) inv + d_a)(1 + e), |e| <= 2^-24. With s the relative slack
// of meet8 and tmin >= 0, every axis's entry t' <= tnear (1 + s) + E and
// exit t' >= tfar (1 - s) - E, so a box the exact segment meets has
// tn' - E <= (tf' + E)(1 + s) / (1 - s): the test tn' <= tf' (1 + 4 s) + 3 E
// (fused, so rounded once, down by at most 2^-24 relative, inside the 4 s)
// never rejects it. tnear = tn' for pruning against tmax (1 + 4 s) + 3 E.
[[gnu::always_inline]] inline int meet8_fma(const BvhNode& n, const BoxRay8& r, v8f tmax, v8f& tnear) {
  const char* base = reinterpret_cast<const char*>(&n);
  v8f t0[3], t1[3];
  for (int a = 0; a < 3; ++a) {
    t0[a] = fmsub(load8(reinterpret_cast<const float*>(base + r.planes[a])), r.inv[a], r.oi[a]);
    t1[a] = fmsub(load8(reinterpret_cast<const float*>(base + r.planes[3 + a])), r.inv[a], r.oi[a]);
  }
  // No NaN here: inv and oi are finite and nonzero-safe (empty children's
  // +-inf planes give +-inf).
  const v8f n01 = t0[0] > t0[1] ? t0[0] : t0[1], n2 = t0[2] > r.tmin ? t0[2] : r.tmin;
  const v8f f01 = t1[0] < t1[1] ? t1[0] : t1[1], f2 = t1[2] < tmax ? t1[2] : tmax;
  const v8f tn = n01 > n2 ? n01 : n2, tf = f01 < f2 ? f01 : f2;
  tnear = tn;
  return movemask_avx(tn <= fmadd(tf, splat(1 + 4 * Bvh::kRelSlack), r.abs_slack));
}

#pragma GCC diagnostic pop

}  // namespace bvh_detail

namespace bvh_detail {

// The children of node n whose boxes the ray meets: kFused, meet8_fma (the
// ray has fma_ok); otherwise meet8, or every child where float cannot hold
// the ray (tnear then -inf).
template <bool kFused>
[[gnu::always_inline]] inline int children_met(const BvhNode& n, const BoxRay& r, const BoxRay8& r8, float tmax_f,
                                               v8f tmax_v, v8f& tnv) {
  if constexpr (kFused) {
    return meet8_fma(n, r8, tmax_v, tnv);
  } else if (r.exact) {
    return meet8(n, r8, tmax_f, tnv);
  } else {
    int mask = 0;
    for (int i = 0; i < 8; ++i) mask |= n.child[i] != Bvh::kEmpty ? 1 << i : 0;
    tnv = splat(-INFINITY);
    return mask;
  }
}

// Asks for a node's four lines (Embree does the same for every child met):
// the loads overlap instead of following one another down the tree.
[[gnu::always_inline]] inline void prefetch_lines(const BvhNode& n) {
  const char* p = reinterpret_cast<const char*>(&n);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
  __builtin_prefetch(p + 192);
}
// Node c's lines and, with kNeighbours (bvh.prefetch_neighbours), those of
// nodes c - 1 and c + 1 (of `count`). Why the neighbours: the build lays
// nodes and leaves out depth first, so neighbours in memory are neighbours
// in space, and rays traced in image order (camera rays, then their shadow
// rays) meet next the nodes and leaves beside the ones this ray meets.
// Where the tree outgrows the last-level cache, a node or leaf first met in
// a pass over the image comes from memory; asked for one ray early, it is
// there when the next ray meets it. Measured on the dragon's shadow rays
// (871k triangles, 90 MB of nodes and leaves; per ray 0.32 leaves and 0.11
// nodes not met before in the pass): the leaves' neighbours +6%, the nodes'
// as well +8%; one side only, or also the leaves two apart, gained less,
// and every leaf child of the node met cost 4%. On the bunny (7 MB, in
// cache) the extra requests cost 2-4%, hence the owner's size rule. A
// template parameter, not a test per node: the test cost 3% on the dragon.
template <bool kNeighbours>
[[gnu::always_inline]] inline void prefetch_node(const Bvh& bvh, std::uint32_t c, std::size_t count) {
  prefetch_lines(bvh.nodes[c]);
  if constexpr (kNeighbours) {
    if (c + 1 < count) prefetch_lines(bvh.nodes[c + 1]);
    if (c > 0) prefetch_lines(bvh.nodes[c - 1]);
  }
}
// The leaf at `first` (its first slot) asked for through the caller's
// leaf_prefetch and, with kNeighbours, the leaves beside it in memory (slots
// first - 4 and first + 4, of `slots`).
template <bool kNeighbours, class LeafPrefetch>
[[gnu::always_inline]] inline void prefetch_leaf(LeafPrefetch& leaf_prefetch, std::uint32_t first, std::size_t slots) {
  leaf_prefetch(first);
  if constexpr (kNeighbours) {
    if (first + 4 < slots) leaf_prefetch(first + 4);
    if (first >= 4) leaf_prefetch(first - 4);
  }
}

// traverse's loop for any hit (kClosest false), in node order without
// sorting. The leaves a node meets are tested at once, in child order,
// after every child met has been asked for; only nodes go on the stack
// (the last pushed taken next). Against pushing leaves and nodes alike
// and taking the last: shadow rays 0-2% faster on the bunny and the
// dragon (a leaf no longer makes a round trip through the stack, and a
// step of the loop no longer asks whether it holds a leaf). Other orders
// measured slower: nodes before leaves by 2%, leaves in reverse child
// order by 1-3%.
template <bool kFused, bool kNeighbours, class T, class Leaf, class LeafPrefetch>
[[gnu::always_inline]] inline void traverse_any_loop(const Bvh& bvh, const BoxRay& r, const T& tmax, Leaf&& leaf,
                                                     LeafPrefetch&& leaf_prefetch) {
  std::uint32_t stack[(Bvh::kWidth - 1) * Bvh::kMaxDepth + 4];
  int top = 0;
  const std::size_t node_count = bvh.nodes.size(), slots = bvh.order.size();
  const float tmax_f = above(double(tmax));
  const v8f tmax_v = splat(tmax_f);
  const BoxRay8 r8 = widen(r);
  std::uint32_t cur = 0;  // the root is a node (a lone leaf gets one)
  for (;;) {
    const BvhNode& n = bvh.nodes[cur];
    v8f tnv;
    const int mask = children_met<kFused>(n, r, r8, tmax_f, tmax_v, tnv);
    std::uint32_t leaves[Bvh::kWidth];
    int nl = 0;
    for (int m = mask; m; m &= m - 1) {
      const std::uint32_t c = n.child[__builtin_ctz(unsigned(m))];
      if (Bvh::is_leaf(c)) {
        prefetch_leaf<kNeighbours>(leaf_prefetch, Bvh::leaf_first(c), slots);
        leaves[nl++] = c;
      } else {
        prefetch_node<kNeighbours>(bvh, c, node_count);
        stack[top++] = c;
      }
    }
    for (int k = 0; k < nl; ++k)
      if (leaf(Bvh::leaf_first(leaves[k]), Bvh::leaf_count(leaves[k]))) return;
    if (top == 0) return;
    cur = stack[--top];
  }
}

// traverse's loop for the closest hit: the nearest child met first, the
// others pushed with their tnear; `tmax` re-read after every leaf (the leaf
// test narrows it) and boxes entered beyond it skipped.
template <bool kFused, bool kNeighbours, class T, class Leaf, class LeafPrefetch>
[[gnu::always_inline]] inline void traverse_closest_loop(const Bvh& bvh, const BoxRay& r, const T& tmax, Leaf&& leaf,
                                                         LeafPrefetch&& leaf_prefetch) {
  const std::size_t node_count = bvh.nodes.size(), slots = bvh.order.size();
  struct Entry {
    std::uint32_t node;
    float tnear;
  };
  Entry stack[(Bvh::kWidth - 1) * Bvh::kMaxDepth + 4];
  int top = 0;
  float tmax_f = above(double(tmax));
  v8f tmax_v = splat(tmax_f);
  // What a box's tnear must exceed to be skipped (see meet8, meet8_fma).
  const float prune_scale = r.nonneg ? 1 + 4 * Bvh::kRelSlack : 1.f;
  const float prune_add = kFused ? r.abs_slack : 0.f;
  auto prune_of = [&](float t) __attribute__((always_inline)) {
    if constexpr (kFused)
      return __builtin_fmaf(t, prune_scale, prune_add);
    else
      return t * prune_scale;
  };
  float prune = prune_of(tmax_f);
  const BoxRay8 r8 = widen(r);
  std::uint32_t cur = 0;  // the root is a node (a lone leaf gets one)
  for (;;) {
    if (Bvh::is_leaf(cur)) {
      if (leaf(Bvh::leaf_first(cur), Bvh::leaf_count(cur))) return;
      tmax_f = above(double(tmax));
      tmax_v = splat(tmax_f);
      prune = prune_of(tmax_f);
    } else {
      const BvhNode& n = bvh.nodes[cur];
      alignas(32) float tn_mem[8];
      v8f tnv;
      int mask = children_met<kFused>(n, r, r8, tmax_f, tmax_v, tnv);
      if constexpr (!kFused) __builtin_memcpy(tn_mem, &tnv, sizeof tn_mem);
      // Child k's tnear.
      auto tn = [&](int k) __attribute__((always_inline)) {
        if constexpr (kFused)
          return lane_avx(tnv, k);
        else
          return tn_mem[k];
      };
      if (mask) {
        // Ask for every child met now: its node's lines, or its leaf's data.
        for (int m = mask; m; m &= m - 1) {
          const std::uint32_t c = n.child[__builtin_ctz(unsigned(m))];
          if (Bvh::is_leaf(c))
            prefetch_leaf<kNeighbours>(leaf_prefetch, Bvh::leaf_first(c), slots);
          else
            prefetch_node<kNeighbours>(bvh, c, node_count);
        }
        const int i = __builtin_ctz(unsigned(mask));
        mask &= mask - 1;
        if (!mask) {  // one child: straight to it
          cur = n.child[i];
          continue;
        }
        const int j = __builtin_ctz(unsigned(mask));
        mask &= mask - 1;
        if (!mask) {  // two children (the usual case): the nearer first
          const bool swap = tn(j) < tn(i);
          const int nearer = swap ? j : i, farther = swap ? i : j;
          stack[top++] = {n.child[farther], tn(farther)};
          cur = n.child[nearer];
          continue;
        }
        // More: push all sorted so the nearest is on top, then take it.
        const int base = top;
        stack[top++] = {n.child[i], tn(i)};
        for (mask |= 1 << j; mask; mask &= mask - 1) {
          const int k0 = __builtin_ctz(unsigned(mask));
          const Entry c{n.child[k0], tn(k0)};
          int k = top++;
          while (k > base && stack[k - 1].tnear < c.tnear) {
            stack[k] = stack[k - 1];
            --k;
          }
          stack[k] = c;
        }
        cur = stack[--top].node;
        continue;
      }
    }
    // Next from the stack, skipping boxes entered beyond the closest hit.
    for (;;) {
      if (top == 0) return;
      const Entry e = stack[--top];
      if (e.tnear > prune) continue;
      cur = e.node;
      break;
    }
  }
}

}  // namespace bvh_detail

// Visits the leaves whose boxes the ray's window meets; `leaf(first_slot,
// count)` returns true to stop, `leaf_prefetch(first_slot)` may ask for a
// leaf's data when its box is met (with bvh.prefetch_neighbours, for the
// leaves either side of it in memory as well). kClosest: nearest box first, `tmax`
// re-read after every leaf (closest-hit shrinks it) and boxes entered
// beyond it skipped (traverse_closest_loop); otherwise (any hit) in node
// order, without sorting (traverse_any_loop).
// Always inlined, so that it is compiled for the ISA of its caller; kFma
// only from callers compiled for AVX2 and FMA (meet8_fma's instructions).
// kNeighbourLoops false: for a BVH whose owner never sets
// prefetch_neighbours (the tracer's object BVH), only the loops without the
// neighbours' requests are compiled. Each loop inlines the caller's leaf
// test, which for the object BVH holds every object's own traversal: the
// loops it never runs doubled the code, and the compile time, of its callers.
template <bool kClosest, bool kFma = false, bool kNeighbourLoops = true, class T, class Leaf, class LeafPrefetch>
[[gnu::always_inline]] inline void traverse(const Bvh& bvh, const Vec3<T>& o, const Vec3<T>& d, T tmin, const T& tmax,
                                            Leaf&& leaf, LeafPrefetch&& leaf_prefetch) {
  using namespace bvh_detail;
  if (bvh.nodes.empty()) return;
  const BoxRay r = box_ray(o, d, tmin);
  auto loops = [&](auto neighbours) __attribute__((always_inline)) {
    constexpr bool kN = decltype(neighbours)::value;
    if constexpr (!kClosest) {
      if constexpr (kFma) {
        if (r.fma_ok) return traverse_any_loop<true, kN>(bvh, r, tmax, leaf, leaf_prefetch);
      }
      traverse_any_loop<false, kN>(bvh, r, tmax, leaf, leaf_prefetch);
    } else {
      if constexpr (kFma) {
        if (r.fma_ok) return traverse_closest_loop<true, kN>(bvh, r, tmax, leaf, leaf_prefetch);
      }
      traverse_closest_loop<false, kN>(bvh, r, tmax, leaf, leaf_prefetch);
    }
  };
  if constexpr (kNeighbourLoops) {
    if (bvh.prefetch_neighbours) return loops(std::true_type{});
  }
  loops(std::false_type{});
}

template <bool kClosest, bool kFma = false, bool kNeighbourLoops = true, class T, class Leaf>
[[gnu::always_inline]] inline void traverse(const Bvh& bvh, const Vec3<T>& o, const Vec3<T>& d, T tmin, const T& tmax,
                                            Leaf&& leaf) {
  traverse<kClosest, kFma, kNeighbourLoops>(bvh, o, d, tmin, tmax, leaf, [](std::uint32_t) {});
}

}  // namespace ra
