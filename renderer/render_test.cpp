// The tracer against values worked out by hand from POV-Ray's equations
// (../shared/POVRAY.md): hits, shading, shadows, reflection depth, and
// determinism across thread counts.
#include "render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scene/camera.h"
#include "errors.h"

namespace ra {
namespace {

Scene parse(const std::string& json) { return parse_scene_json(json, "test.json"); }

RenderOptions opts() {
  RenderOptions o;
  o.progress = false;
  return o;
}

void expect_color(const Color& got, const Color& want, double tol = 1e-12) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

const char* kUnitSphere = R"({"lights": [], "objects": [{"sphere": {"center": [0,0,0], "radius": 1}}]})";

TEST(Intersect, SphereFromOutsideHitsTheNearSide) {
  Scene s = parse(kUnitSphere);
  Tracer tr(s, opts());
  auto h = tr.intersect({{0, 0, 5}, {0, 0, -1}});
  ASSERT_TRUE(h);
  EXPECT_DOUBLE_EQ(h->t, 4.0);
}

TEST(Intersect, SphereFromInsideHitsTheFarSide) {
  Scene s = parse(kUnitSphere);
  Tracer tr(s, opts());
  auto h = tr.intersect({{0, 0, 0.5}, {0, 0, -1}});
  ASSERT_TRUE(h);
  EXPECT_DOUBLE_EQ(h->t, 1.5);
}

TEST(Intersect, SphereBehindTheOriginIsMissed) {
  Scene s = parse(kUnitSphere);
  Tracer tr(s, opts());
  EXPECT_FALSE(tr.intersect({{0, 0, 5}, {0, 0, 1}}));
}

// occluded() asks only "anything in the window?": the unit sphere spans
// t in [4, 6] along this ray, so a window ending at 3.9 is clear, one
// ending at 4.1 or starting inside (at 5) is not; in float too.
TEST(Occluded, HonoursTheRayWindowInBothPrecisions) {
  Scene s = parse(kUnitSphere);
  for (bool dbl : {true, false}) {
    RenderOptions o = opts();
    o.use_double = dbl;
    Tracer tr(s, o);
    EXPECT_FALSE(tr.occluded({{0, 0, 5}, {0, 0, -1}, 0.0, 3.9})) << dbl;
    EXPECT_TRUE(tr.occluded({{0, 0, 5}, {0, 0, -1}, 0.0, 4.1})) << dbl;
    EXPECT_TRUE(tr.occluded({{0, 0, 5}, {0, 0, -1}, 5.0, 100.0})) << dbl;
    EXPECT_FALSE(tr.occluded({{0, 0, 5}, {0, 0, 1}, 0.0, 100.0})) << dbl;
  }
}

TEST(Intersect, PlaneFromBothSidesAndParallel) {
  Scene s = parse(R"({"lights": [], "objects": [{"plane": {"normal": [0,2,0], "offset": 2}}]})");
  // normal [0,2,0] with offset 2 is the plane y = 1 (POV scales both).
  Tracer tr(s, opts());
  auto above = tr.intersect({{0, 5, 0}, {0, -2, 0}});
  ASSERT_TRUE(above);
  EXPECT_DOUBLE_EQ(above->t, 2.0);  // direction of length 2: 4 units in t = 2
  auto below = tr.intersect({{3, -1, 0}, {0, 1, 0}});
  ASSERT_TRUE(below);
  EXPECT_DOUBLE_EQ(below->t, 2.0);
  EXPECT_FALSE(tr.intersect({{0, 5, 0}, {1, 0, 0}}));           // parallel
  EXPECT_FALSE(tr.intersect({{0, 5, 0}, {0, 1, 0}}));           // plane behind
  EXPECT_FALSE(tr.intersect({{0, 5, 0}, {0, -1, 0}, 0, 3.9}));  // the plane at t = 4: beyond tmax
  EXPECT_TRUE(tr.intersect({{0, 5, 0}, {0, -1, 0}, 0, 4.1}));   // within it
}

TEST(Intersect, TriangleAndTheNearestObjectWins) {
  Scene s = parse(R"({"lights": [], "objects": [
      {"sphere": {"center": [0,0,-10], "radius": 1}},
      {"triangle": [[-1,-1,-2], [1,-1,-2], [0,1,-2]]}]})");
  Tracer tr(s, opts());
  auto h = tr.intersect({{0, 0, 0}, {0, 0, -1}});
  ASSERT_TRUE(h);
  EXPECT_EQ(h->object, 1);
  EXPECT_DOUBLE_EQ(h->t, 2.0);
  // The hit (0,0) is A + b1 (B-A) + b2 (C-A): b1 = 1/4, b2 = 1/2.
  EXPECT_DOUBLE_EQ(h->b1, 0.25);
  EXPECT_DOUBLE_EQ(h->b2, 0.5);
}

// A grey plane y = 0 seen along a ray that hits the origin.
std::string lit_plane(const std::string& light, const std::string& extra_material = "") {
  return R"({"lights": [)" + light + R"(], "objects": [{"plane": {"normal": [0,1,0], "offset": 0},
      "material": {"color": [0.5, 0.5, 0.5])" +
         extra_material + "}}]}";
}

TEST(Shading, AmbientOnlyWithoutLights) {
  Scene s = parse(lit_plane(""));
  Tracer tr(s, opts());
  // C * ambient * ambient_light = 0.5 * 0.1 * 1
  expect_color(tr.trace({{0, 1, 0}, {0, -1, 0}}), {0.05, 0.05, 0.05});
}

TEST(Shading, DiffuseIsKdTimesCosineTimesPigment) {
  // Light at (10, 10, 0): L = (1,1,0)/sqrt2, N.L = 1/sqrt2.
  // I = 0.5*0.1 + 0.6 * (1/sqrt2) * 0.5 = 0.05 + 0.3/sqrt2.
  Scene s = parse(lit_plane(R"({"position": [10, 10, 0]})"));
  Tracer tr(s, opts());
  const double want = 0.05 + 0.3 / std::sqrt(2.0);
  expect_color(tr.trace({{0, 1, 0}, {0, -1, 0}}), {want, want, want});
}

TEST(Shading, PhongIsNotTintedByThePigment) {
  // Ray along (1,-1,0)/sqrt2 to the origin; its mirror direction is
  // (1,1,0)/sqrt2, which points exactly at the light: R.L = 1, so phong adds
  // 0.5 * 1^2 * Lc = 0.5 in every channel, whatever the pigment; diffuse adds
  // 0.6 * (1/sqrt2) * C * Lc with light colour (1, 0.5, 0.25).
  Scene s =
      parse(lit_plane(R"({"position": [10, 10, 0], "color": [1, 0.5, 0.25]})", R"(, "phong": 0.5, "phong_size": 2)"));
  Tracer tr(s, opts());
  const double diff = 0.6 / std::sqrt(2.0) * 0.5;
  expect_color(tr.trace({{-1, 1, 0}, Vec3d{1, -1, 0}}),
               {0.05 + diff * 1 + 0.5, 0.05 + diff * 0.5 + 0.5 * 0.5, 0.05 + diff * 0.25 + 0.5 * 0.25});
}

TEST(Shading, LightBelowTheSurfaceSeenFromAboveAddsNothing) {
  Scene s = parse(lit_plane(R"({"position": [0, -10, 0]})"));
  Tracer tr(s, opts());
  expect_color(tr.trace({{0, 1, 0}, {0, -1, 0}}), {0.05, 0.05, 0.05});
}

TEST(Shadows, ASphereBetweenPointAndLightLeavesOnlyAmbient) {
  Scene s = parse(R"({"lights": [{"position": [0, 10, 0]}], "objects": [
      {"plane": {"normal": [0,1,0], "offset": 0}, "material": {"color": [0.5,0.5,0.5]}},
      {"sphere": {"center": [0, 5, 0], "radius": 1}}]})");
  Tracer tr(s, opts());
  expect_color(tr.trace({{0.1, 1, 0}, {0, -1, 0}}), {0.05, 0.05, 0.05});
  // Away from the shadow, the light shines: 0.05 + 0.6 * N.L * 0.5 with
  // L from (5, 0, 0) to (0, 10, 0).
  const double nl = 10 / std::sqrt(125.0);
  const double lit = 0.05 + 0.3 * nl;
  expect_color(tr.trace({{5, 1, 0}, {0, -1, 0}}), {lit, lit, lit});
}

// Two white mirrors y = 0 and y = 2 facing each other, ambient 0.1,
// reflection 0.5, no lights: a vertical ray bounces between them and level k
// sees I_k = 0.1 + 0.5 I_{k+1}, with black beyond max_depth.
std::string mirrors(int max_depth) {
  return R"({"lights": [], "max_depth": )" + std::to_string(max_depth) + R"(, "background": [1,1,1], "objects": [
      {"plane": {"normal": [0,1,0], "offset": 0}, "material": {"reflection": 0.5, "diffuse": 0}},
      {"plane": {"normal": [0,1,0], "offset": 2}, "material": {"reflection": 0.5, "diffuse": 0}}]})";
}

TEST(Reflection, DepthOneIsAmbientOnly) {
  Scene s = parse(mirrors(1));
  Tracer tr(s, opts());
  expect_color(tr.trace({{0, 1, 0}, {0, -1, 0}}), {0.1, 0.1, 0.1});
}

TEST(Reflection, DepthThreeSumsTwoBouncesThenBlack) {
  Scene s = parse(mirrors(3));
  Tracer tr(s, opts());
  // I3 = 0.1, I2 = 0.1 + 0.05, I1 = 0.1 + 0.5 * 0.15 = 0.175.
  expect_color(tr.trace({{0, 1, 0}, {0, -1, 0}}), {0.175, 0.175, 0.175});
}

TEST(Reflection, ReflectedRayThatEscapesSeesTheBackground) {
  Scene s = parse(R"({"lights": [], "background": [0.2, 0.4, 0.6], "objects": [
      {"plane": {"normal": [0,1,0], "offset": 0}, "material": {"reflection": [1, 0.5, 0], "ambient": 0}}]})");
  Tracer tr(s, opts());
  expect_color(tr.trace({{0, 1, 0}, {1, -1, 0}}), {0.2, 0.2, 0.0});
}

TEST(Render, ImageIsIdenticalForAnyThreadCount) {
  Scene s = parse(R"({"width": 97, "height": 61, "camera": {"position": [0, 2, 6], "look_at": [0, 0.5, 0]},
      "lights": [{"position": [-3, 5, 4]}, {"position": [4, 3, 2], "color": [0.3, 0.3, 0.5]}],
      "objects": [{"sphere": {"center": [0, 1, 0], "radius": 1}, "material": {"phong": 0.7, "reflection": 0.3}},
                  {"sphere": {"center": [1.6, 0.5, 1], "radius": 0.5}, "material": {"color": [0.2, 0.9, 0.3]}},
                  {"triangle": [[-3, 0.01, -2], [-1, 0.01, -2], [-2, 2, -2]]},
                  {"plane": {"normal": [0, 1, 0], "offset": 0}, "material": {"reflection": 0.2}}]})");
  RenderOptions o = opts();
  o.threads = 1;
  const Image one = Tracer(s, o).render();
  for (int n : {2, 3, 8}) {
    o.threads = n;
    const Image many = Tracer(s, o).render();
    ASSERT_EQ(many.rgb.size(), one.rgb.size());
    EXPECT_TRUE(many.rgb == one.rgb) << "threads = " << n;
  }
  // And the image is not trivially uniform.
  EXPECT_NE(one.at(48, 30)[0], one.at(0, 0)[0]);
}

TEST(Render, SupersamplingAveragesTheSubpixelCentres) {
  // A 1x1 image whose pixel straddles the sphere's silhouette: the 2x2
  // average equals the mean of the four sub-pixel traces.
  Scene s = parse(
      R"({"width": 1, "height": 1, "lights": [], "camera": {"position": [1, 1, 5], "look_at": [1, 1, 0], "vfov": 30},
      "objects": [{"sphere": {"center": [0,0,0], "radius": 1.414}, "material": {"ambient": 1}}]})");
  RenderOptions o = opts();
  o.samples_per_axis = 2;
  Tracer tr(s, o);
  Camera cam(s.camera, 1, 1);
  Color sum{0, 0, 0};
  for (double y : {0.25, 0.75})
    for (double x : {0.25, 0.75}) {
      Ray<double> r = cam.ray(x, y);
      r.tmin = kPovMinIsectDepth;
      sum += tr.trace(r);
    }
  expect_color(tr.pixel(0, 0), sum / 4.0);
}

// In float, normal-offset must move a secondary ray's origin by float's
// error bound for the hit point, not double's: on a triangle 1e4 across seen
// near the origin, the float kernel's error in t for the ray's own triangle
// (o - v0 is rounded at 1e4's scale, ~1e-3) is far larger than p's own
// rounding (~1e-7). With double's bound the shadow ray re-hits its own
// triangle on a large share of pixels; with float's, none does, so every
// pixel is as lit as in double.
TEST(Render, FloatNormalOffsetNeverShadowsAHugeTriangleOnItself) {
  Scene s = parse(R"({"width": 64, "height": 48,
      "camera": {"position": [0.3, 1.7, 2.1], "look_at": [0.1, 0.2, 0.05]},
      "lights": [{"position": [3, 9, 5]}],
      "objects": [{"triangle": [[-9000.3, 0.11, -7000.7], [9300.1, -0.13, -6000.9], [100.7, 0.07, 9800.3]]}]})");
  for (const char* method : {"moller", "watertight", "baldwin"}) {
    RenderOptions o = opts();
    o.self_intersection = SelfIntersection::normal_offset;
    o.triangle_method = method;
    const Image lit = Tracer(s, o).render();
    o.use_double = false;
    const Image f = Tracer(s, o).render();
    int shadowed = 0;
    for (std::size_t i = 0; i < f.rgb.size(); ++i)
      if (f.rgb[i] < lit.rgb[i] - 0.1) ++shadowed;
    EXPECT_EQ(shadowed, 0) << method << ": float pixels self-shadowed";
    // The light does reach the surface: the image is not ambient-only.
    EXPECT_GT(lit.at(32, 24)[0], 0.2) << method;
  }
}

}  // namespace
}  // namespace ra
