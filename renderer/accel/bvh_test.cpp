// accel/bvh.h: the BVH answers every ray exactly as the loop over all
// triangles (--accel none) does, on the rays where a float box test is most
// likely to go wrong: origins far from the mesh, on its box planes, inside
// it, axis-parallel directions, tiny and huge |d|, windows ending at a hit
// or starting behind the origin (the two-sided slack of meet8).
#include "accel/bvh.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "render.h"

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
    const Tracer bvh(scene, o);
    o.simd = false;
    const Tracer bvh_sse2(scene, o);
    for (int i = 0; i < 4000; ++i) {
      Ray<double> r;
      const Vec3d target = at + Vec3d{u(rng), u(rng), u(rng)} * 1.1;
      r.o = i % 3 == 0 ? at + Vec3d{u(rng), u(rng), u(rng)} * far : at + Vec3d{u(rng), u(rng), u(rng)};
      r.d = target - r.o;
      if (i % 4 == 1) r.o[i % 3] = at[i % 3];  // origin on a plane of the flat triangles
      if (i % 5 == 2) {                          // axis-parallel
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
      const auto b = bvh.intersect(r), c = bvh_sse2.intersect(r);
      ASSERT_EQ(a.has_value(), b.has_value()) << i;
      ASSERT_EQ(a.has_value(), c.has_value()) << i;
      if (a) {
        EXPECT_TRUE(a->t == b->t && a->prim == b->prim && a->b1 == b->b1 && a->b2 == b->b2) << i;
        EXPECT_TRUE(a->t == c->t && a->prim == c->prim && a->b1 == c->b1 && a->b2 == c->b2) << i;
        ++*hits;
      }
      EXPECT_EQ(none.occluded(r), bvh.occluded(r)) << i;
      EXPECT_EQ(none.occluded(r), bvh_sse2.occluded(r)) << i;
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

}  // namespace
}  // namespace ra
