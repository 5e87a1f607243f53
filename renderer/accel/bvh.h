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
//  - 1/d rounded to float (from double for double rays), the subtraction
//    and the product add 3 roundings:
//    all of it is relative to t, covered by widening [tnear, tfar] by
//    kRelSlack = 2^-20 (16 float ulps) of their magnitudes;
//  - d_a = 0 gives 1/d_a = +-inf: (plane - o_a) * inf is +-inf, or NaN when
//    o_a lies exactly on the plane, which the min/max below ignore (the slab
//    then constrains nothing), as Williams et al. 2005 intend;
//  - a ray float cannot hold (|o| > 1e30, |1/d| below float's normal range
//    or above it while d != 0) visits every leaf instead.
#pragma once
#include <immintrin.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
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
  static constexpr int kMaxLeaf = 4;       // triangles per leaf; every leaf owns 4 slots
  static constexpr int kMaxDepth = 128;    // binary depth bound (build); 8-wide depth is below it
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  static constexpr std::uint32_t kLeaf = 0x80000000u;      // child word: leaf flag
  static constexpr std::uint32_t kNoTriangle = 0xFFFFFFFFu;  // order[] of an unused slot
  static constexpr float kRelSlack = 1.0f / (1 << 20);

  std::vector<BvhNode> nodes;       // nodes[0] is the root (empty for an empty mesh)
  std::vector<std::uint32_t> order;  // slot -> triangle; leaf k's slots are 4k .. 4k + count - 1

  static bool is_leaf(std::uint32_t c) { return c != kEmpty && (c & kLeaf); }
  // A leaf's first slot (a multiple of 4) and its number of triangles (1..4).
  static std::uint32_t leaf_first(std::uint32_t c) { return (c & 0x1FFFFFFFu) << 2; }
  static std::uint32_t leaf_count(std::uint32_t c) { return ((c >> 29) & 3u) + 1; }
  static std::uint32_t make_leaf(std::uint32_t leaf_index, std::uint32_t count) {
    return kLeaf | ((count - 1) << 29) | leaf_index;
  }

  // Builds over triangles given by their boxes; `pad` widens every box.
  // Uses up to `threads` threads (0: all cores); the tree (nodes and order,
  // byte for byte) does not depend on the thread count.
  static Bvh build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad, int threads = 0);
  // The same with triangles [begin, end)'s boxes written by `boxes` to
  // lo[0 .. end - begin) and hi[...] on the build's threads, a piece at a
  // time (no array of all the boxes).
  using BoxFn = std::function<void(std::size_t begin, std::size_t end, Vec3d* lo, Vec3d* hi)>;
  static Bvh build(std::size_t n, const BoxFn& boxes, double pad, int threads = 0);
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
[[gnu::always_inline]] inline v8f splat(float x) { return v8f{} + x; }
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

// The ray as the box test sees it.
struct BoxRay {
  v8f o[3], inv[3];
  // Byte offsets in BvhNode of each axis's near and far planes (hi is the
  // near plane when d_a < 0, or -0).
  unsigned near_off[3], far_off[3];
  v8f tmin;
  bool exact = true;  // false: float cannot hold this ray; visit every leaf
  // tmin >= 0 (every ray the tracer casts): then tnear >= 0, and tfar may
  // carry all the slack (Ize 2013's one-sided test, 2 operations fewer).
  bool nonneg = false;
};

// One vector division for the three 1/d_a: in float for float rays (the
// correctly rounded 1/d), in double then rounded for double rays.
template <class T>
[[gnu::always_inline]] inline BoxRay box_ray(const Vec3<T>& o, const Vec3<T>& d, T tmin) {
  typedef float v4 __attribute__((vector_size(16)));
  typedef double v4d __attribute__((vector_size(32)));
  typedef int v4m __attribute__((vector_size(16)));
  v4 inv;
  if constexpr (sizeof(T) == sizeof(float)) {
    inv = v4{1, 1, 1, 1} / v4{d.x, d.y, d.z, 1};
  } else {
    inv = __builtin_convertvector(v4d{1, 1, 1, 1} / v4d{d.x, d.y, d.z, 1}, v4);
  }
  const v4 of{float(o.x), float(o.y), float(o.z), 0};
  const v4 dz{float(d.x == 0), float(d.y == 0), float(d.z == 0), 1};
  const v4 abs_inv = (v4)((v4m)inv & 0x7FFFFFFF), abs_o = (v4)((v4m)of & 0x7FFFFFFF);
  // Float must hold the origin, and 1/d_a must be a normal float unless d_a = 0.
  const v4m ok = (abs_o <= 1e30f) & ((dz != 0) | ((abs_inv >= std::numeric_limits<float>::min()) &
                                                   (abs_inv <= std::numeric_limits<float>::max())));
  BoxRay b;
  b.exact = _mm_movemask_ps((__m128)ok) == 0xF;
  for (int a = 0; a < 3; ++a) {
    b.o[a] = splat(of[a]);
    b.inv[a] = splat(inv[a]);
    const bool near_hi = std::signbit(inv[a]);
    b.near_off[a] = unsigned(near_hi ? offsetof(BvhNode, hi) : offsetof(BvhNode, lo)) + 32u * unsigned(a);
    b.far_off[a] = unsigned(near_hi ? offsetof(BvhNode, lo) : offsetof(BvhNode, hi)) + 32u * unsigned(a);
  }
  const float tmin_f = round_down(double(tmin));
  b.tmin = splat(tmin_f);
  b.nonneg = tmin_f >= 0;
  return b;
}

// Bit i set: child i's box meets [tmin, tmax]; tnear gets each box's
// lower bound of the entry t (for ordering and pruning).
[[gnu::always_inline]] inline int meet8(const BvhNode& n, const BoxRay& r, float tmax, v8f& tnear) {
  v8f tn = r.tmin, tf = splat(tmax);
  for (int a = 0; a < 3; ++a) {
    const char* base = reinterpret_cast<const char*>(&n);
    const v8f nearp = load8(reinterpret_cast<const float*>(base + r.near_off[a]));
    const v8f farp = load8(reinterpret_cast<const float*>(base + r.far_off[a]));
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

#pragma GCC diagnostic pop

}  // namespace bvh_detail

// Visits the leaves whose boxes the ray's window meets; `leaf(first_slot,
// count)` returns true to stop. kClosest: nearest box first, `tmax` re-read
// after every leaf (closest-hit shrinks it) and boxes entered beyond it
// skipped; otherwise (any hit) in node order, without sorting. The nearest
// child hit is visited next without going through the stack.
// Always inlined, so that it is compiled for the ISA of its caller.
template <bool kClosest, class T, class Leaf>
[[gnu::always_inline]] inline void traverse(const Bvh& bvh, const Vec3<T>& o, const Vec3<T>& d, T tmin, const T& tmax,
                                            Leaf&& leaf) {
  using namespace bvh_detail;
  if (bvh.nodes.empty()) return;
  const BoxRay r = box_ray(o, d, tmin);
  struct Entry {
    std::uint32_t node;
    float tnear;
  };
  Entry stack[(Bvh::kWidth - 1) * Bvh::kMaxDepth + 4];
  int top = 0;
  float tmax_f = round_up(double(tmax));
  // What a box's tnear must exceed to be skipped (see meet8).
  const float prune_scale = r.nonneg ? 1 + 4 * Bvh::kRelSlack : 1.f;
  float prune = tmax_f * prune_scale;
  std::uint32_t cur = 0;  // the root is a node (a lone leaf gets one)
  for (;;) {
    if (Bvh::is_leaf(cur)) {
      if (leaf(Bvh::leaf_first(cur), Bvh::leaf_count(cur))) return;
      if constexpr (kClosest) {
        tmax_f = round_up(double(tmax));
        prune = tmax_f * prune_scale;
      }
    } else {
      const BvhNode& n = bvh.nodes[cur];
      alignas(32) float tn[8];
      int mask;
      if (r.exact) {
        v8f tnv;
        mask = meet8(n, r, tmax_f, tnv);
        __builtin_memcpy(tn, &tnv, sizeof tn);
      } else {
        mask = 0;
        for (int i = 0; i < 8; ++i) {
          mask |= n.child[i] != Bvh::kEmpty ? 1 << i : 0;
          tn[i] = -INFINITY;
        }
      }
      if (mask) {
        int i = __builtin_ctz(unsigned(mask));
        mask &= mask - 1;
        if (!mask) {  // one child: straight to it
          cur = n.child[i];
          continue;
        }
        if constexpr (!kClosest) {
          cur = n.child[i];
          for (; mask; mask &= mask - 1) {
            const int j = __builtin_ctz(unsigned(mask));
            stack[top++] = {n.child[j], tn[j]};
          }
          continue;
        } else {
          // Push all hit children sorted so the nearest is on top, then
          // take it.
          const int base = top;
          stack[top++] = {n.child[i], tn[i]};
          for (; mask; mask &= mask - 1) {
            const int j = __builtin_ctz(unsigned(mask));
            const Entry c{n.child[j], tn[j]};
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
    }
    // Next from the stack, skipping boxes entered beyond the closest hit.
    for (;;) {
      if (top == 0) return;
      const Entry e = stack[--top];
      if (kClosest && e.tnear > prune) continue;
      cur = e.node;
      break;
    }
  }
}

}  // namespace ra
