// POV-Ray 3.7's mesh2 hit point and smooth-normal weights (renderer/pov_mesh.h),
// checked against values measured from POV-Ray itself.
#include "pov_mesh.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <utility>

namespace ra {
namespace {

// float(0.1) exactly.
constexpr double kFloatTenth = 0.100000001490116119384765625;

TEST(PovMesh, ToFloat32RoundsEveryComponent) {
  // GCC 12.2 at -O2/-O3 compiled Vec3d(Vec3f(p)) to p in x and y.
  const Vec3d r = to_float32(Vec3d{0.1, 0.1, 0.1});
  EXPECT_EQ(r.x, kFloatTenth);
  EXPECT_EQ(r.y, kFloatTenth);
  EXPECT_EQ(r.z, kFloatTenth);
}

// Triangle 62648 of corpus/ladder-100k-bunny (bunny_glmark2.obj, `f 32226
// 31728 32110`) seen through pixel (165, 206), with its area-weighted vertex
// normals as the exporter writes them. POV-Ray 3.7.0.10 was measured on this
// very ray (the exported scene with the texture replaced, 16-bit output):
//  - pigment { function { (z - z0) * 1e5 + 0.5 } }, ambient 1, diffuse 0:
//    the hit point's z is 0.6571964671342 (+-8e-11), 1.3e-7 below the plane
//    of the (float32) vertices along this ray;
//  - pigment 1, ambient A = 0.5 - 1000 * 0.2886, diffuse 1000: N.L is
//    0.2885992447 (+-8e-9).
// With that N.L the bunny's colour 0.08 + 0.64 N.L is 67.4994/255 (POV's 67);
// the hit on the plane of the float32 vertices gives N.L = 0.2886030,
// 67.50001/255 (68; our render, on the OBJ's double vertices, 0.2886042).
struct BunnyPixel {
  Ray<double> ray{{0, 0, 3.868784480420409}, {0.018188219474865021, -0.28605108810469498, -0.9580417337811824}};
  Vec3d a{0.0612528, -0.96097, 0.655007}, b{0.076102, -0.957424, 0.655162}, c{0.0579516, -0.950385, 0.666709};
  Vec3d na{0.11886690677484779, -0.8821078845526591, 0.4558029601525338};
  Vec3d nb{0.18163001007223528, -0.7732075754853818, 0.6075858660742341};
  Vec3d nc{0.2545751055099446, -0.44942612753722655, 0.8562754647550594};
  Vec3d light{0, 0, 3.868784480420409};

  // N.L at p with weights (b1, b2) of b and c, normals as POV stores them.
  double n_dot_l(const Vec3d& p, double b1, double b2) const {
    const Vec3d fa = to_float32(normalize(na)), fb = to_float32(normalize(nb)), fc = to_float32(normalize(nc));
    Vec3d n = normalize(fa + (fb - fa) * b1 + (fc - fa) * b2);
    if (dot(n, ray.d) > 0) n = -n;
    return dot(n, normalize(light - p));
  }
};

constexpr double kPovHitZ = 0.6571964671341958;
constexpr double kPovNdotL = 0.28859924467841613;

TEST(PovMesh, BunnyPixelHitPointAndNormalMatchPovRay) {
  const BunnyPixel s;
  const PovMeshHit h = pov_mesh_hit(s.ray, s.a, s.b, s.c);
  ASSERT_TRUE(h.ok);
  EXPECT_NEAR(h.p.z, kPovHitZ, 3e-10);
  EXPECT_NEAR(s.n_dot_l(h.p, h.b1, h.b2), kPovNdotL, 2e-8);
  const double level = (0.08 + 0.64 * s.n_dot_l(h.p, h.b1, h.b2)) * 255;
  EXPECT_LT(level, 67.5);
}

TEST(PovMesh, BunnyPixelOnTheVertexPlaneDoesNotMatch) {
  // The hit on the plane of the float32 vertices (what the renderer computes
  // without pov_mesh_hit): barycentrics by Cramer's rule in double.
  const BunnyPixel s;
  const Vec3d a = to_float32(s.a), b = to_float32(s.b), c = to_float32(s.c);
  const Vec3d e1 = b - a, e2 = c - a, pv = cross(s.ray.d, e2);
  const double det = dot(e1, pv);
  const Vec3d tv = s.ray.o - a, qv = cross(tv, e1);
  const double b1 = dot(tv, pv) / det, b2 = dot(s.ray.d, qv) / det;
  const Vec3d p = a * (1 - b1 - b2) + b * b1 + c * b2;
  EXPECT_GT(std::fabs(p.z - kPovHitZ), 1e-7);
  EXPECT_GT(std::fabs(s.n_dot_l(p, b1, b2) - kPovNdotL), 3e-6);
  EXPECT_GT((0.08 + 0.64 * s.n_dot_l(p, b1, b2)) * 255, 67.5);
  // And pov_mesh_hit is not that point: it moves the hit off the vertex plane.
  const PovMeshHit h = pov_mesh_hit(s.ray, s.a, s.b, s.c);
  ASSERT_TRUE(h.ok);
  EXPECT_GT(std::fabs(h.p.z - p.z), 1e-7);
}

TEST(PovMesh, WeightsDoNotDependOnTheVertexSwap) {
  // Listing a triangle as (b, a, c) makes POV swap the other way; the point
  // and each vertex's weight must stay the same.
  const BunnyPixel s;
  const PovMeshHit h = pov_mesh_hit(s.ray, s.a, s.b, s.c);
  const PovMeshHit g = pov_mesh_hit(s.ray, s.b, s.a, s.c);
  ASSERT_TRUE(h.ok && g.ok);
  EXPECT_NEAR(length(h.p - g.p), 0, 1e-12);
  EXPECT_NEAR(1 - h.b1 - h.b2, g.b1, 1e-7);  // a's weight
  EXPECT_NEAR(h.b1, 1 - g.b1 - g.b2, 1e-7);  // b's weight
  EXPECT_NEAR(h.b2, g.b2, 1e-7);
  // And the weights locate the point: sum of weight * vertex is p, up to
  // float32 Perp and the point's distance from the vertex plane.
  const Vec3d a = to_float32(s.a), b = to_float32(s.b), c = to_float32(s.c);
  EXPECT_NEAR(length(a * (1 - h.b1 - h.b2) + b * h.b1 + c * h.b2 - h.p), 0, 1e-6);
}

TEST(PovMesh, ParallelRayIsNoHit) {
  const Ray<double> r{{0, 0, 1}, {1, 0, 0}};
  EXPECT_FALSE(pov_mesh_hit(r, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}).ok);
}

// POV's mesh2 test: a point on an edge is inside (each edge test rejects
// only `<`), one beyond the edge is not, in either vertex order (the swap
// makes the edge tests face the same way).
TEST(PovMesh, InsideTestKeepsEdgesAndRejectsOutside) {
  const Vec3d a{0, 0, 0}, b{4, 0, 0}, c{0, 4, 0};
  const Ray<double> on_edge{{2, 0, 5}, {0, 0, -1}};  // meets the edge a-b at (2, 0, 0)
  const Ray<double> outside{{2, -0.001, 5}, {0, 0, -1}};
  const Ray<double> inside{{1, 1, 5}, {0, 0, -1}};
  for (bool swap : {false, true}) {
    const Vec3d& p = swap ? b : a;
    const Vec3d& q = swap ? a : b;
    ASSERT_TRUE(pov_mesh_intersect(inside, p, q, c).has_value());
    EXPECT_EQ(*pov_mesh_intersect(inside, p, q, c), 5.0);
    EXPECT_TRUE(pov_mesh_intersect(on_edge, p, q, c).has_value());
    EXPECT_FALSE(pov_mesh_intersect(outside, p, q, c).has_value());
  }
  // Behind the origin, closer than POV's 1e-6, or degenerate: no hit.
  EXPECT_FALSE(pov_mesh_intersect(Ray<double>{{1, 1, -1}, {0, 0, -1}}, a, b, c).has_value());
  EXPECT_FALSE(pov_mesh_intersect(Ray<double>{{1, 1, 1e-7}, {0, 0, -1}}, a, b, c).has_value());
  EXPECT_FALSE(pov_mesh_intersect(inside, a, b, Vec3d{8, 0, 0}).has_value());
}

// Mesh::UVCoord gives each vertex its own UV and the centroid their mean.
TEST(PovMesh, UvAtVerticesAndCentroid) {
  const Vec3d a{0, 0, 0}, b{3, 0, 0}, c{0, 2, 1};
  const std::array<double, 2> ua{0.25, 0.5}, ub{0.75, 0.125}, uc{0.5, 1};
  for (const auto& [p, want] : {std::pair{a, ua}, std::pair{b, ub}, std::pair{c, uc}}) {
    const auto uv = pov_mesh_uv(p, a, b, c, ua, ub, uc);
    EXPECT_NEAR(uv[0], want[0], 1e-15);
    EXPECT_NEAR(uv[1], want[1], 1e-15);
  }
  const auto mid = pov_mesh_uv((a + b + c) / 3.0, a, b, c, ua, ub, uc);
  EXPECT_NEAR(mid[0], 0.5, 1e-15);
  EXPECT_NEAR(mid[1], 1.625 / 3, 1e-15);
}

}  // namespace
}  // namespace ra
