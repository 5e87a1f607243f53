// accel/bvh.h: the BVH answers every ray exactly as the loop over all
// triangles (--accel none) does, on the rays where a float box test is most
// likely to go wrong: origins far from the mesh, on its box planes, inside
// it, axis-parallel directions, tiny and huge |d|, windows ending at a hit
// or starting behind the origin (the two-sided slack of meet8). And the
// build's structure: the same tree for every thread count, every triangle
// in one leaf, every box holding what is below it.
#include "accel/bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include <memory>
#include <cstring>
#include <random>

#include "../render.h"

namespace ra {
namespace {

// A soup of small triangles in [-1, 1]^3 shifted by `at`, plus triangles in
// the coordinate planes through `at` (so box planes sit on axis-parallel rays).
Scene soup(const Vec3d& at, std::uint64_t seed) {
  auto set = std::make_shared<TriangleSet>();
  set->name = "soup";
  set->materials.resize(1);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), s(-0.1, 0.1);
  for (int i = 0; i < 3000; ++i) {
    const Vec3d c{u(rng), u(rng), u(rng)};
    MeshTriangle3 t;
    for (int k = 0; k < 3; ++k) {
      t.v[k] = int(set->positions.size());
      Vec3d p = at + c + Vec3d{s(rng), s(rng), s(rng)};
      if (i % 10 == 0) p[i / 10 % 3] = at[i / 10 % 3];  // flat in an axis plane
      set->positions.push_back(p);
    }
    set->triangles.push_back(t);
  }
  Scene scene;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  scene.objects.push_back(o);
  return scene;
}

void compare(const Vec3d& at, double far, std::uint64_t seed, int* hits) {
  const Scene scene = soup(at, seed);
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (bool dbl : {false, true}) {
    RenderOptions o;
    o.use_double = dbl;
    o.threads = 1;
    o.accel = Accel::none;
    const Tracer none(scene, o);
    o.accel = Accel::bvh;
    const Tracer bvh(scene, o);  // AVX-512 or AVX2, as the CPU has
    // The traversal that also asks for the nodes and leaves beside those it
    // meets (by_size leaves it off on this small mesh): the same answers.
    o.neighbour_prefetch = RenderOptions::NeighbourPrefetch::always;
    const Tracer bvh_nb(scene, o);
    o.neighbour_prefetch = RenderOptions::NeighbourPrefetch::by_size;
    o.avx512 = false;
    const Tracer bvh_avx2(scene, o);
    o.simd = false;
    o.neighbour_prefetch = RenderOptions::NeighbourPrefetch::always;
    const Tracer bvh_sse2(scene, o);
    for (int i = 0; i < 4000; ++i) {
      Ray<double> r;
      const Vec3d target = at + Vec3d{u(rng), u(rng), u(rng)} * 1.1;
      r.o = i % 3 == 0 ? at + Vec3d{u(rng), u(rng), u(rng)} * far : at + Vec3d{u(rng), u(rng), u(rng)};
      r.d = target - r.o;
      if (i % 4 == 1) r.o[i % 3] = at[i % 3];  // origin on a plane of the flat triangles
      if (i % 5 == 2) {                        // axis-parallel
        r.d = Vec3d{0, 0, 0};
        r.d[i % 3] = (i & 8) ? -1 : 1;
        r.o[i % 3] = at[i % 3] - r.d[i % 3] * 3;
      }
      if (i % 7 == 3) r.d = r.d * 1e-20;
      if (i % 7 == 4) r.d = r.d * 1e20;
      if (i % 11 == 7) r.tmin = -0.5;  // a window reaching behind the origin
      // Directions whose 1/d float cannot hold (the visit-every-leaf path),
      // or whose t overflows float (a float kernel's hit at t = inf).
      if (i % 13 == 6) r.d = r.d * 1e-40;
      if (i % 13 == 8) r.d = r.d * 1e40;
      const auto a = none.intersect(r);
      if (i % 6 == 5 && a) r.tmax = a->t;  // a window ending at the hit
      const auto b = bvh.intersect(r), c = bvh_sse2.intersect(r), e = bvh_avx2.intersect(r), f = bvh_nb.intersect(r);
      ASSERT_EQ(a.has_value(), b.has_value()) << i;
      ASSERT_EQ(a.has_value(), c.has_value()) << i;
      ASSERT_EQ(a.has_value(), e.has_value()) << i;
      ASSERT_EQ(a.has_value(), f.has_value()) << i;
      if (a) {
        EXPECT_TRUE(a->t == b->t && a->prim == b->prim && a->b1 == b->b1 && a->b2 == b->b2) << i;
        EXPECT_TRUE(a->t == c->t && a->prim == c->prim && a->b1 == c->b1 && a->b2 == c->b2) << i;
        EXPECT_TRUE(a->t == e->t && a->prim == e->prim && a->b1 == e->b1 && a->b2 == e->b2) << i;
        EXPECT_TRUE(a->t == f->t && a->prim == f->prim && a->b1 == f->b1 && a->b2 == f->b2) << i;
        ++*hits;
      }
      EXPECT_EQ(none.occluded(r), bvh.occluded(r)) << i;
      EXPECT_EQ(none.occluded(r), bvh_sse2.occluded(r)) << i;
      EXPECT_EQ(none.occluded(r), bvh_avx2.occluded(r)) << i;
      EXPECT_EQ(none.occluded(r), bvh_nb.occluded(r)) << i;
    }
  }
}

TEST(Bvh, SameHitsAsEveryTriangleNearTheOrigin) {
  int hits = 0;
  compare({0, 0, 0}, 50, 1, &hits);
  EXPECT_GT(hits, 1000);
}

// Far from the origin float's spacing is coarse (Embree's WatertightTest
// placement): the padding and the relative slack must still hold.
TEST(Bvh, SameHitsAsEveryTriangleFarFromTheOrigin) {
  int hits = 0;
  compare({148376, 1234, -223423}, 1e4, 2, &hits);
  EXPECT_GT(hits, 1000);
}

// meet8_fma (the AVX2+FMA path) on its own, against the slab test in long
// double (64-bit mantissa: exact enough, its error is 2^-40 of the float
// test's slack): every box the segment [tmin, tmax] meets must be in the
// mask, and its tnear must not exceed the pruning bound for tmax. Boxes
// hug points of the ray, or graze it from one side, near and far from the
// origin.
// Compiled for AVX2 and FMA under GCC, where meet8_fma is their
// instructions; clang's meet8_fma is lane-by-lane generic code (bvh.h), and
// clang rejects 8-float vectors crossing between AVX and non-AVX code.
#if defined(__clang__)
int fused_mask(const BvhNode& n, const bvh_detail::BoxRay& r, float tmax, float* tnear) {
#else
[[gnu::target("avx2,fma")]] int fused_mask(const BvhNode& n, const bvh_detail::BoxRay& r, float tmax, float* tnear) {
#endif
  const bvh_detail::BoxRay8 w = bvh_detail::widen(r);
  bvh_detail::v8f tn;
  const int m = bvh_detail::meet8_fma(n, w, bvh_detail::splat(tmax), tn);
  std::memcpy(tnear, &tn, sizeof tn);
  return m;
}

bool slab_meets(const Vec3d& o, const Vec3d& d, double tmin, double tmax, const BvhNode& n, int i) {
  long double lo = tmin, hi = tmax;
  for (int a = 0; a < 3; ++a) {
    const long double t0 = ((long double)n.lo[a][i] - o[a]) / d[a], t1 = ((long double)n.hi[a][i] - o[a]) / d[a];
    lo = std::max(lo, std::min(t0, t1));
    hi = std::min(hi, std::max(t0, t1));
  }
  return lo <= hi;
}

// The traversal's tmax in float: never below the double, whatever its
// magnitude (subnormal floats, float's overflow, exact floats, both signs).
TEST(Bvh, AboveIsNeverBelowItsArgument) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> mant(1, 2);
  std::uniform_int_distribution<int> ex(-160, 127);  // below -FLT_MAX: -inf + inf, a NaN (an empty window)
  for (int i = 0; i < 200000; ++i) {
    double x = std::ldexp(mant(rng), ex(rng));
    if (i % 3 == 0) x = double(float(x));        // exactly a float
    if (i % 5 == 0) x = std::nextafter(x, 0.0);  // just below one
    if (i % 2) x = -x;
    const float a = bvh_detail::above(x);
    ASSERT_GE(double(a), x) << std::hexfloat << x;
    ASSERT_LE(double(a), x + std::fabs(x) * 0x1p-21 + 2e-30) << std::hexfloat << x;  // and tight
  }
  EXPECT_EQ(bvh_detail::above(INFINITY), INFINITY);
  EXPECT_GE(double(bvh_detail::above(3.5e38)), 3.5e38);  // beyond float: +inf
  // Zero and values too small for a normal float: above them, and close.
  for (const double x : {0.0, -0.0, 1e-40, -1e-40, 1e-300}) {
    EXPECT_GE(double(bvh_detail::above(x)), x) << x;
    EXPECT_LE(double(bvh_detail::above(x)), x + 2e-30) << x;
  }
}

TEST(Bvh, FusedBoxTestNeverRejectsABoxTheSegmentMeets) {
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) GTEST_SKIP() << "no AVX2+FMA";
  using bvh_detail::round_down;
  using bvh_detail::round_up;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), w(0, 1);
  int met = 0, rays = 0;
  for (int i = 0; i < 20000; ++i) {
    const double scale = i % 3 == 0 ? 1 : i % 3 == 1 ? 1e3 : 1e5;
    const Vec3d o = Vec3d{u(rng), u(rng), u(rng)} * scale;
    Vec3d d{u(rng), u(rng), u(rng)};
    if (i % 5 == 1) d[i % 3] *= 1e-6;                // nearly axis-parallel
    if (i % 7 == 2) d = d * (i % 2 ? 1e-12 : 1e12);  // tiny and huge |d|
    const double tmin = i % 4 == 0 ? 0 : w(rng) * 1e-3 * scale / length(d);
    const double tmax = i % 6 == 0 ? INFINITY : (0.5 + 2 * w(rng)) * scale / length(d);
    const bvh_detail::BoxRay r = bvh_detail::box_ray(o, d, tmin);
    if (!r.fma_ok) continue;
    ++rays;
    BvhNode n{};
    for (int c = 0; c < 8; ++c) {
      // A point of the ray (in long double), a box around it of half-size h,
      // moved off the ray by h + a hair on one axis half of the time.
      const long double t = tmin + (long double)w(rng) * (std::isinf(tmax) ? 3 * scale / length(d) : tmax - tmin);
      const double h = c % 4 == 0 ? 0 : scale * std::pow(10.0, -1 - 7 * w(rng));
      for (int a = 0; a < 3; ++a) {
        long double p = o[a] + t * d[a];
        if (c % 2 && a == c % 3) p += (c & 4 ? 1 : -1) * (h + scale * 1e-9 * w(rng));
        n.lo[a][c] = round_down(double(p - h));
        n.hi[a][c] = round_up(double(p + h));
      }
    }
    const float tmax_f = bvh_detail::above(tmax);  // as traverse rounds it
    float tn[8];
    const int mask = fused_mask(n, r, tmax_f, tn);
    const float prune = std::fma(tmax_f, 1 + 4 * Bvh::kRelSlack, r.abs_slack);
    for (int c = 0; c < 8; ++c) {
      if (!slab_meets(o, d, tmin, tmax, n, c)) continue;
      ++met;
      ASSERT_TRUE((mask >> c) & 1) << "ray " << i << " box " << c;
      ASSERT_LE(tn[c], prune) << "ray " << i << " box " << c;
    }
  }
  EXPECT_GT(rays, 15000);
  EXPECT_GT(met, 40000);
}

// Boxes of `n` random small triangles; `clumps` > 0 puts them on that many
// points only (coinciding centroids: the build's halving fallback).
void random_boxes(int n, int clumps, std::uint64_t seed, std::vector<Vec3d>& lo, std::vector<Vec3d>& hi) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-10, 10), s(0, 0.3);
  std::vector<Vec3d> points;
  for (int i = 0; i < clumps; ++i) points.push_back({u(rng), u(rng), u(rng)});
  lo.clear();
  hi.clear();
  for (int i = 0; i < n; ++i) {
    const Vec3d c = clumps > 0 ? points[std::size_t(i % clumps)] : Vec3d{u(rng), u(rng), u(rng)};
    const Vec3d e = clumps > 0 ? Vec3d{0.1, 0.1, 0.1} : Vec3d{s(rng), s(rng), s(rng)};
    lo.push_back(c - e);
    hi.push_back(c + e);
  }
}

bool same_tree(const Bvh& a, const Bvh& b) {
  return a.nodes.size() == b.nodes.size() && a.order == b.order &&
         std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)) == 0;
}

// Walks the tree from the root: every node reached once, every triangle in
// exactly one leaf, each child's box holding the boxes below it (a leaf's
// triangles, or every box of its node), no leaf deeper than the traversal
// stack allows. Returns the number of nodes reached.
std::size_t check_structure(const Bvh& b, const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi) {
  std::vector<int> seen(lo.size(), 0), reached(b.nodes.size(), 0);
  std::size_t nodes = 0, leaves = 0;
  struct Item {
    std::uint32_t node;
    int depth;
  };
  std::vector<Item> todo{{0, 1}};
  while (!todo.empty()) {
    const Item it = todo.back();
    todo.pop_back();
    EXPECT_LT(it.node, b.nodes.size());
    if (it.node >= b.nodes.size() || reached[it.node]++) {
      ADD_FAILURE() << "node " << it.node << " reached twice or out of range";
      continue;
    }
    ++nodes;
    EXPECT_LE(it.depth, Bvh::kMaxDepth);
    const BvhNode& n = b.nodes[it.node];
    int used = 0;
    for (int i = 0; i < Bvh::kWidth; ++i) {
      const std::uint32_t c = n.child[i];
      if (c == Bvh::kEmpty) continue;
      ++used;
      if (Bvh::is_leaf(c)) {
        const unsigned first = Bvh::leaf_first(c), count = Bvh::leaf_count(c);
        ++leaves;
        EXPECT_EQ(first % 4, 0u);  // a leaf is one aligned block of 4 slots
        EXPECT_LE(count, unsigned(Bvh::kMaxLeaf));
        for (unsigned s = first; s < first + 4; ++s) {
          if (s >= first + count) {
            EXPECT_EQ(b.order[s], Bvh::kNoTriangle);
            continue;
          }
          ++seen[b.order[s]];
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(n.lo[a][i], lo[b.order[s]][a]);
            EXPECT_GE(n.hi[a][i], hi[b.order[s]][a]);
          }
        }
        continue;
      }
      const BvhNode& k = b.nodes[c];
      for (int j = 0; j < Bvh::kWidth; ++j) {
        if (k.child[j] == Bvh::kEmpty) continue;
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(n.lo[a][i], k.lo[a][j]);
          EXPECT_GE(n.hi[a][i], k.hi[a][j]);
        }
      }
      todo.push_back({c, it.depth + 1});
    }
    EXPECT_GE(used, 1);
  }
  for (std::size_t t = 0; t < seen.size(); ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
  EXPECT_EQ(nodes, b.nodes.size());
  EXPECT_EQ(leaves * 4, b.order.size());  // no slot outside a leaf
  return nodes;
}

// Small boxes spread over a cube, built with the default thread count.
TEST(Bvh, LeavesHoldAtMostFourTrianglesAndEveryTriangleOnce) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-10, 10);
  std::vector<Vec3d> lo, hi;
  for (int i = 0; i < 5000; ++i) {
    const Vec3d c{u(rng), u(rng), u(rng)};
    lo.push_back(c - Vec3d{0.1, 0.1, 0.1});
    hi.push_back(c + Vec3d{0.1, 0.2, 0.05});
  }
  check_structure(Bvh::build(lo, hi, 0), lo, hi);
}

// Large enough for the splits spread over threads and the subtree tasks.
TEST(BvhBuild, SameTreeForEveryThreadCountAndEveryTriangleOnce) {
  std::vector<Vec3d> lo, hi;
  random_boxes(100000, 0, 7, lo, hi);
  const Bvh one = Bvh::build(lo, hi, 1e-6, 1);
  EXPECT_GT(check_structure(one, lo, hi), 100000u / 32);
  for (int t : {2, 7}) {
    const Bvh many = Bvh::build(lo, hi, 1e-6, t);
    EXPECT_TRUE(same_tree(one, many)) << t << " threads";
  }
}

// The AVX2 build (bvh_build.inc compiled for AVX2) and the baseline one
// make the same tree byte for byte, on one thread and on several, also far
// from the origin (where the rounding to float of every box matters) and
// when every centroid coincides (the halving path).
TEST(BvhBuild, SameTreeWithAndWithoutAvx2) {
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) GTEST_SKIP() << "no AVX2+FMA";
  for (int kind : {0, 3}) {
    std::vector<Vec3d> lo, hi;
    random_boxes(kind == 0 ? 150000 : 20000, kind, 11, lo, hi);
    for (std::vector<Vec3d>* v : {&lo, &hi})
      for (Vec3d& p : *v) p = p + Vec3d{123456.75, -0.1, 3e4};
    for (int t : {1, 2}) {
      const Bvh avx2 = Bvh::build(lo, hi, 1e-3, t, true), base = Bvh::build(lo, hi, 1e-3, t, false);
      check_structure(base, lo, hi);
      EXPECT_TRUE(same_tree(avx2, base)) << "boxes " << kind << ", " << t << " threads";
    }
  }
}

// Coinciding centroids give SAH nothing to split: the build halves instead.
TEST(BvhBuild, CoincidingCentroidsAreHalved) {
  std::vector<Vec3d> lo, hi;
  random_boxes(50000, 3, 8, lo, hi);
  const Bvh one = Bvh::build(lo, hi, 0, 1);
  check_structure(one, lo, hi);
  EXPECT_TRUE(same_tree(one, Bvh::build(lo, hi, 0, 2)));
}

TEST(BvhBuild, TinyMeshes) {
  for (int n : {0, 1, 4, 5, 9, 33}) {
    std::vector<Vec3d> lo, hi;
    random_boxes(n, 0, 9, lo, hi);
    const Bvh b = Bvh::build(lo, hi, 0, 2);
    if (n == 0) {
      EXPECT_TRUE(b.nodes.empty());
      continue;
    }
    check_structure(b, lo, hi);
  }
}

}  // namespace
}  // namespace ra
