// The four self-intersection strategies of renderer/spawn.h, checked against
// their definitions:
//  - eps (document 001): origin unchanged, accept t > 1e-5, shadow rays end
//    at the light;
//  - pov (POV-Ray 3.7, POVRAY.md): shadow rays (1e-3, dist - 1e-3), other
//    rays t >= 1e-4, origin unchanged;
//  - normal-offset (pbrt-v4 OffsetRayOrigin): p + n dot(|n|, err), then one
//    ulp outward per component;
//  - ulp-offset (Ray Tracing Gems ch. 6): each component with |p| >= 1/32
//    moves int(256 n) representable floats in the direction of n (for double
//    int(256 2^29 n) doubles, as spawn.h documents), each one with
//    |p| < 1/32 becomes p + n / 65536.
// Expected values come from those definitions, evaluated independently of
// spawn.h: std::nextafter steps instead of bit arithmetic, exact sums in a
// wider type.
#include "spawn.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <random>

#include "render.h"
#include "scene/scene.h"

namespace ra {
namespace {

// p moved k representable values towards +inf (k > 0) or -inf (k < 0).
template <class T>
T steps(T p, long long k) {
  const T to = k > 0 ? std::numeric_limits<T>::infinity() : -std::numeric_limits<T>::infinity();
  for (long long i = 0; i < std::llabs(k); ++i) p = std::nextafter(p, to);
  return p;
}

TEST(Spawn, NamesRoundTrip) {
  for (auto s :
       {SelfIntersection::eps, SelfIntersection::pov, SelfIntersection::normal_offset, SelfIntersection::ulp_offset})
    EXPECT_EQ(parse_self_intersection(self_intersection_name(s)), s);
  EXPECT_FALSE(parse_self_intersection("ulp"));
  EXPECT_FALSE(parse_self_intersection(""));
}

TEST(Spawn, EpsKeepsTheOriginAndAcceptsTAbove1e5) {
  const Vec3d p{1.5, -2, 0.25}, n{0, 0, 1}, dir{0, 0.6, 0.8};
  const Ray<double> r = spawn_ray(SelfIntersection::eps, p, Vec3d{}, n, dir, false, 0.0);
  EXPECT_EQ(r.o, p);
  EXPECT_EQ(r.d, dir);
  EXPECT_EQ(r.tmin, 0.00001);
  EXPECT_EQ(r.tmax, std::numeric_limits<double>::infinity());
  const Ray<double> s = spawn_ray(SelfIntersection::eps, p, Vec3d{}, n, dir, true, 7.0);
  EXPECT_EQ(s.o, p);
  EXPECT_EQ(s.tmin, 0.00001);
  EXPECT_EQ(s.tmax, 7.0);  // up to the light itself
}

TEST(Spawn, PovUsesPovRaysWindows) {
  const Vec3d p{1.5, -2, 0.25}, n{0, 0, 1}, dir{0, 0.6, 0.8};
  const Ray<double> r = spawn_ray(SelfIntersection::pov, p, Vec3d{}, n, dir, false, 0.0);
  EXPECT_EQ(r.o, p);
  EXPECT_EQ(r.tmin, 1e-4);  // MIN_ISECT_DEPTH
  EXPECT_EQ(r.tmax, std::numeric_limits<double>::infinity());
  const Ray<double> s = spawn_ray(SelfIntersection::pov, p, Vec3d{}, n, dir, true, 7.0);
  EXPECT_EQ(s.o, p);
  EXPECT_EQ(s.tmin, 1e-3);
  EXPECT_EQ(s.tmax, 7.0 - 1e-3);
  // Float rays get the same windows, rounded to float.
  const Ray<float> f =
      spawn_ray(SelfIntersection::pov, Vec3f{1, 2, 3}, Vec3f{}, Vec3f{0, 0, 1}, Vec3f{0, 0, 1}, true, 5.0f);
  EXPECT_EQ(f.tmin, 1e-3f);
  EXPECT_EQ(f.tmax, 5.0f - 1e-3f);
}

// float: p = (1, -2, 0.01), n = (0.48, -0.64, 0.6) (unit, exactly in
// decimal). x: int(256 * 0.48) = int(122.88) = 122 floats up; y: int(-163.84)
// = -163, i.e. 163 floats towards -inf (n.y < 0), so away from zero as p.y is
// negative; z: |0.01| < 1/32, so 0.01 + 0.6 / 65536.
TEST(Spawn, UlpOffsetFloatMovesByInt256NUlpsAndSmallComponentsByNOver65536) {
  const Vec3f p{1.0f, -2.0f, 0.01f}, n{0.48f, -0.64f, 0.6f};
  const Vec3f o = detail::ulp_offset(p, n);
  EXPECT_EQ(o.x, steps(1.0f, 122));
  EXPECT_EQ(o.x, 1.0f + 122 * 0x1p-23f);  // by hand: ulp(1) = 2^-23
  EXPECT_EQ(o.y, steps(-2.0f, -163));
  EXPECT_EQ(o.y, -2.0f - 163 * 0x1p-22f);  // ulp(2) = 2^-22
  // One rounding of the exact sum (n / 65536 is exact: a power of two).
  EXPECT_EQ(o.z, float(double(0.01f) + double(0.6f) / 65536.0));
}

TEST(Spawn, UlpOffsetCrossesBinadesOneRepresentableValueAtATime) {
  // 1.0 moved down: the ulps below 1 are 2^-24, half those above.
  const Vec3f o = detail::ulp_offset(Vec3f{1.0f, -1.0f, 0.5f}, Vec3f{-0.6f, 0.8f, 0.0f});
  EXPECT_EQ(o.x, 1.0f - 153 * 0x1p-24f);   // int(-153.6) = -153
  EXPECT_EQ(o.y, -1.0f + 204 * 0x1p-24f);  // int(204.8) = 204, towards zero
  EXPECT_EQ(o.z, 0.5f);                    // n.z = 0: no move
  // |p| exactly 1/32 is not "within 1/32": it moves in ulps.
  const Vec3f e = detail::ulp_offset(Vec3f{0.03125f, 0, 0}, Vec3f{1, 0, 0});
  EXPECT_EQ(e.x, steps(0.03125f, 256));
  // Just below 1/32: p + n / 65536.
  const float below = std::nextafter(0.03125f, 0.0f);
  EXPECT_EQ(detail::ulp_offset(Vec3f{below, 0, 0}, Vec3f{1, 0, 0}).x, float(double(below) + 1.0 / 65536));
}

// double: the chapter's 256 ulps scaled by 2^29 (52 - 23 mantissa bits), so
// the move is int(256 * 2^29 * n) doubles: about the float move in size.
TEST(Spawn, UlpOffsetDoubleScalesTheStepBy2To29) {
  const Vec3d o = detail::ulp_offset(Vec3d{1.0, -2.0, 0.01}, Vec3d{0.5, -0.25, 0.6});
  // 256 * 2^29 * 0.5 = 2^36 doubles of 2^-52 above 1: 2^-16 exactly.
  EXPECT_EQ(o.x, 1.0 + 0x1p-16);
  // 2^35 doubles of 2^-51 below -2: 2^-16.
  EXPECT_EQ(o.y, -2.0 - 0x1p-16);
  EXPECT_EQ(o.z, 0.01 + 0.6 / 65536);
  // Same size as the float offset, 256 * 0.5 float ulps of 1 = 2^-16.
  EXPECT_EQ(double(detail::ulp_offset(Vec3f{1.0f, 0, 0}, Vec3f{0.5f, 0, 0}).x) - 1.0, 0x1p-16);
}

// The offset origin lies strictly on the side the normal points to, for
// random points at all scales and random unit normals: every component
// moves with the sign of n (or not at all) and at least one moves, so
// dot(o - p, n) > 0 holds exactly. Differences of nearby floats and
// products of two floats are exact in double, so the check is exact.
TEST(Spawn, UlpOffsetOriginIsStrictlyOnTheNormalsSide) {
  const unsigned seed = 6061;
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::uniform_int_distribution<int> exp(-12, 12);
  for (int i = 0; i < 20000; ++i) {
    Vec3f p, n{g(rng), g(rng), g(rng)};
    n = n / length(n);
    for (int c = 0; c < 3; ++c) p[c] = std::ldexp(g(rng), exp(rng));
    const Vec3f o = detail::ulp_offset(p, n);
    double d = 0;
    for (int c = 0; c < 3; ++c) {
      const double move = double(o[c]) - double(p[c]);
      ASSERT_GE(move * double(n[c]), 0) << "seed " << seed << " case " << i << " component " << c;
      if (n[c] == 0) {
        ASSERT_EQ(move, 0);
      }
      d += move * double(n[c]);
    }
    ASSERT_GT(d, 0) << "seed " << seed << " case " << i;
  }
}

// spawn_ray turns n to the side the ray leaves towards before offsetting.
TEST(Spawn, OffsetStrategiesFollowTheRaysSideOfTheSurface) {
  const Vec3d p{2.0, 3.0, -4.0}, err{1e-9, 1e-9, 1e-9};
  const Vec3d n{0, 0, 1};
  for (auto s : {SelfIntersection::normal_offset, SelfIntersection::ulp_offset}) {
    const Ray<double> up = spawn_ray(s, p, err, n, Vec3d{0.6, 0, 0.8}, false, 0.0);
    const Ray<double> down = spawn_ray(s, p, err, n, Vec3d{0.6, 0, -0.8}, false, 0.0);
    EXPECT_GT(up.o.z, p.z) << self_intersection_name(s);
    EXPECT_LT(down.o.z, p.z) << self_intersection_name(s);
    EXPECT_EQ(up.o.x, p.x);
    EXPECT_EQ(up.o.y, p.y);
    EXPECT_EQ(up.tmin, 0.0);
    EXPECT_EQ(up.tmax, std::numeric_limits<double>::infinity());
  }
}

// normal-offset: with a zero error bound the origin is p moved one ulp
// outward in each component where n is not zero (spawn.h: "then one ulp
// outward"; an origin left ON the surface would meet it again at t = 0,
// which a window starting at tmin = 0 accepts); with a bound, each
// component moves at least |n_i| dot(|n|, err) outward, so the origin is at
// least that far from the tangent plane: dot(o - p, n) >= d.
TEST(Spawn, NormalOffsetMovesByTheErrorBoundThenOneUlp) {
  const Vec3f p{1.0f, -3.0f, 0.0f};
  const Vec3f n{0.6f, 0.0f, -0.8f};
  const Ray<float> r = spawn_ray(SelfIntersection::normal_offset, p, Vec3f{}, n, Vec3f{0, 0, -1}, false, 0.0f);
  EXPECT_EQ(r.o.x, std::nextafter(1.0f, 2.0f));
  EXPECT_EQ(r.o.y, -3.0f);
  EXPECT_EQ(r.o.z, -std::numeric_limits<float>::denorm_min());

  const unsigned seed = 4242;
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  for (int i = 0; i < 5000; ++i) {
    Vec3f q{g(rng) * 100, g(rng) * 100, g(rng) * 100}, m{g(rng), g(rng), g(rng)};
    m = m / length(m);
    const Vec3f err = abs(q) * 1e-6f;
    const Ray<float> s = spawn_ray(SelfIntersection::normal_offset, q, err, m, m, false, 0.0f);
    const double d = std::abs(double(m.x)) * err.x + std::abs(double(m.y)) * err.y + std::abs(double(m.z)) * err.z;
    double along = 0;
    for (int c = 0; c < 3; ++c) {
      const double move = double(s.o[c]) - double(q[c]);
      ASSERT_GE(move * m[c], 0) << "seed " << seed << " case " << i;
      ASSERT_GE(std::abs(move), std::abs(double(m[c])) * d * (1 - 1e-6)) << "seed " << seed << " case " << i;
      along += move * m[c];
    }
    ASSERT_GE(along, d * (1 - 1e-6)) << "seed " << seed << " case " << i;
  }
}

// Offset shadow rays start at o, not p: tmax is shortened by |o - p| and
// then by gamma(3) so that the ray stops short of the light; tmin is 0.
TEST(Spawn, OffsetShadowRaysStopShortOfTheLight) {
  const Vec3d p{1.0, 2.0, 3.0}, n{0, 1, 0}, dir{0, 1, 0};
  for (auto s : {SelfIntersection::normal_offset, SelfIntersection::ulp_offset}) {
    const Ray<double> r = spawn_ray(s, p, Vec3d{1e-6, 1e-6, 1e-6}, n, dir, true, 10.0);
    EXPECT_EQ(r.tmin, 0.0);
    const double moved = r.o.y - p.y;
    ASSERT_GT(moved, 0);
    EXPECT_LT(r.o.y + r.tmax, p.y + 10.0) << self_intersection_name(s);
    EXPECT_GT(r.tmax, 10.0 - moved - 1e-12) << self_intersection_name(s);
  }
}

// pbrt-v4's gamma(n) = n u / (1 - n u), u = 2^-24 (float), 2^-53 (double).
TEST(Spawn, GammaAndTrianglePointErrorFollowPbrt) {
  EXPECT_EQ(detail::gamma<float>(3), float(3 * 0x1p-24f / (1 - 3 * 0x1p-24f)));
  EXPECT_EQ(detail::gamma<double>(7), 7 * 0x1p-53 / (1 - 7 * 0x1p-53));
  // b1 = b2 = 0.25, b0 = 0.5: gamma(7) (0.5 |A| + 0.25 |B| + 0.25 |C|).
  const Vec3d e = triangle_point_error(Vec3d{4, -8, 0}, Vec3d{0, 4, -16}, Vec3d{8, 0, 4}, 0.25, 0.25);
  const double g7 = 7 * 0x1p-53 / (1 - 7 * 0x1p-53);
  EXPECT_EQ(e.x, (2.0 + 0 + 2) * g7);
  EXPECT_EQ(e.y, (4.0 + 1 + 0) * g7);
  EXPECT_EQ(e.z, (0.0 + 4 + 1) * g7);
}

// Whole renders: a lit triangle in the plane z = 0 (its hit points and their
// error bounds have z exactly 0) must not shadow itself with any strategy.
// Ambient 0, diffuse 1, white, the light straight above the hit point:
// the pixel is N.L = 1 exactly; a self-hit would leave it black.
TEST(Spawn, NoStrategyShadowsAFlatTriangleOnItself) {
  const auto dir = std::filesystem::temp_directory_path() / ("rayaudit_spawn_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "flat.json") << R"({"lights": [{"position": [0.25, 0.125, 4]}],
      "objects": [{"triangle": [[-1, -1, 0], [1, -1, 0], [0, 1, 0]],
                   "material": {"ambient": 0, "diffuse": 1}}]})";
  const Scene scene = load_scene(dir / "flat.json");
  for (auto s :
       {SelfIntersection::eps, SelfIntersection::pov, SelfIntersection::normal_offset, SelfIntersection::ulp_offset})
    for (bool dbl : {true, false}) {
      RenderOptions o;
      o.progress = false;
      o.threads = 1;
      o.self_intersection = s;
      o.use_double = dbl;
      const Tracer tr(scene, o);
      const Color c = tr.trace({{0.25, 0.125, 3}, {0, 0, -1}});
      EXPECT_NEAR(c.x, 1.0, 1e-12) << self_intersection_name(s) << (dbl ? " double" : " float");
    }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ra
