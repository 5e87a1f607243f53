// --accel bvh and sphere against none far from the origin: for every
// triangle method and precision, the same closest hit (t, triangle,
// barycentrics) and the same any-hit answer for rays from far out (a camera
// at 1e5 on the diagonal looking at a unit sphere of small triangles at the
// origin, the case where float's rounding of o - v put Moller's hits 2.5
// units from their triangles and the BVH and the bounding sphere lost a
// third of them), and for the mesh itself far out (1e5, 1e7) and scaled
// (1e-4, 1e4), rays from near and far. Every method whose hits lie within
// rounding of their triangles (all but angles and areas, see SetUp).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>

#include "../registry.h"
#include "../render.h"

namespace ra {
namespace {

// A sphere of radius r at c tessellated into small triangles (a subdivided
// octahedron, 8 * 4^level triangles, shared vertices), outward winding.
Scene sphere_mesh(const Vec3d& c, double r, int level) {
  auto set = std::make_shared<TriangleSet>();
  set->name = "sphere";
  set->materials.resize(1);
  std::vector<Vec3d> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<int, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < level; ++l) {
    std::vector<std::array<int, 3>> g;
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(normalize((v[std::size_t(a)] + v[std::size_t(b)]) * 0.5));
      return mid[key] = int(v.size()) - 1;
    };
    for (const auto& t : f) {
      const int ab = m(t[0], t[1]), bc = m(t[1], t[2]), ca = m(t[2], t[0]);
      g.push_back({t[0], ab, ca});
      g.push_back({t[1], bc, ab});
      g.push_back({t[2], ca, bc});
      g.push_back({ab, bc, ca});
    }
    f = g;
  }
  for (const Vec3d& p : v) set->positions.push_back(c + p * r);
  for (const auto& t : f) {
    MeshTriangle3 tri;
    for (int k = 0; k < 3; ++k) tri.v[k] = t[std::size_t(k)];
    set->triangles.push_back(tri);
  }
  Scene scene;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  scene.objects.push_back(o);
  return scene;
}

struct Counts {
  int hits = 0, rays = 0;
};

// Rays from `from` (each jittered by `jitter`) to random points of the
// sphere's silhouette disc and a little beyond it; every accel must answer
// as none does. Returns the hits none found.
void compare(const Scene& scene, const Method& m, bool dbl, const Vec3d& c, double r, const Vec3d& from, double jitter,
             int rays, std::uint64_t seed, Counts& counts) {
  RenderOptions o;
  o.triangle_method = m.name;
  o.use_double = dbl;
  o.threads = 1;
  o.accel = Accel::none;
  const Tracer none(scene, o);
  o.accel = Accel::sphere;
  const Tracer sphere(scene, o);
  o.accel = Accel::bvh;
  const Tracer bvh(scene, o);
  o.simd = false;
  const Tracer bvh_sse2(scene, o);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::string what = m.name + (dbl ? "/double" : "/float");
  for (int i = 0; i < rays; ++i) {
    Ray<double> ray;
    ray.o = from + Vec3d{u(rng), u(rng), u(rng)} * jitter;
    ray.d = c + Vec3d{u(rng), u(rng), u(rng)} * (1.1 * r) - ray.o;
    if (i % 4 == 1) ray.d = ray.d / length(ray.d);  // unit, as a camera's
    const auto a = none.intersect(ray);
    const auto b = bvh.intersect(ray), s = sphere.intersect(ray), e = bvh_sse2.intersect(ray);
    ASSERT_EQ(a.has_value(), b.has_value()) << what << " ray " << i << " bvh";
    ASSERT_EQ(a.has_value(), s.has_value()) << what << " ray " << i << " sphere";
    ASSERT_EQ(a.has_value(), e.has_value()) << what << " ray " << i << " bvh sse2";
    if (a) {
      ++counts.hits;
      for (const auto& x : {b, s, e})
        ASSERT_TRUE(a->t == x->t && a->prim == x->prim && a->b1 == x->b1 && a->b2 == x->b2)
            << what << " ray " << i << ": t " << a->t << " vs " << x->t << ", triangle " << a->prim << " vs "
            << x->prim;
    }
    const bool occ = none.occluded(ray);
    ASSERT_EQ(occ, bvh.occluded(ray)) << what << " ray " << i << " bvh any-hit";
    ASSERT_EQ(occ, sphere.occluded(ray)) << what << " ray " << i << " sphere any-hit";
    ASSERT_EQ(occ, bvh_sse2.occluded(ray)) << what << " ray " << i << " bvh sse2 any-hit";
    ++counts.rays;
  }
}

class AccelFar : public ::testing::TestWithParam<std::string> {
 protected:
  // angles and areas accept points outside the triangle by absolute
  // tolerances (seeds/000's MINUS_ZERO, 1e-4 of area; seeds/001's epsilon3,
  // 1e-3), whatever the triangle's size, and areas also every point whose
  // Heron product rounds below zero, on an edge's line however far out: no
  // padded box holds their hits, near the origin or far from it.
  void SetUp() override {
    if (GetParam() == "angles" || GetParam() == "areas")
      GTEST_SKIP() << GetParam() << "'s hits are not within rounding of its triangles (absolute tolerances)";
  }
};

// The case that lost a third of the elephant's hits in float: a camera at
// (1e5, 1e5, 1e5) (exactly, as a scene file gives it) and a unit mesh of
// small triangles at the origin.
TEST_P(AccelFar, SameHitsFromACameraFarOnTheDiagonal) {
  const Method& m = *find_method(GetParam());
  const Scene scene = sphere_mesh({0, 0, 0}, 0.5, 4);  // 2,048 triangles
  for (const bool dbl : {false, true}) {
    Counts n;
    compare(scene, m, dbl, {0, 0, 0}, 0.5, {1e5, 1e5, 1e5}, 0, 300, 1, n);
    if (HasFatalFailure()) return;
    EXPECT_GT(n.hits, 50) << m.name;
  }
}

// The mesh far out and scaled, rays from near it and from 1e3 to 1e5 of
// its sizes away.
TEST_P(AccelFar, SameHitsForMeshesFarOutAndScaled) {
  const Method& m = *find_method(GetParam());
  std::uint64_t seed = 10;
  for (const double at : {0.0, 1e5, 1e7})
    for (const double scale : {1e-4, 1e4}) {
      const Vec3d c{at, -0.5 * at, 0.25 * at};
      const Scene scene = sphere_mesh(c, scale, 2);  // 128 triangles
      for (const bool dbl : {false, true})
        for (const double away : {2.0, 1e3, 1e5}) {
          Counts n;
          compare(scene, m, dbl, c, scale, c + Vec3d{0.6, -0.7, 0.4} * (away * scale), 0.5 * away * scale, 60, ++seed,
                  n);
          if (HasFatalFailure()) return;
          // At the origin and scale 1e4 every method sees the mesh (far out,
          // float may collapse it; at 1e-4 a document's absolute epsilon,
          // sameside's, misses it; then every accelerator misses alike): the
          // identity above must have been tested on hits, not misses only.
          if (at == 0.0 && scale > 1) {
            EXPECT_GE(n.hits, 5) << m.name << (dbl ? "/double" : "/float") << " scale " << scale;
          }
        }
    }
}

std::vector<std::string> triangle_methods() {
  std::vector<std::string> out;
  for (const Method& m : methods())
    if (m.kind == Kind::triangle) out.push_back(m.name);
  return out;
}

INSTANTIATE_TEST_SUITE_P(EveryTriangleMethod, AccelFar, ::testing::ValuesIn(triangle_methods()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace ra
