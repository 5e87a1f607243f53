// The watertight method's conservative t bound (pbrt-v4's deltaT, with its
// delta_x/delta_y terms in consistent units; see watertight.h): what it must
// keep, what it may drop by design, and the scale bug it had.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <optional>
#include <random>
#include <tuple>

#include "methods/watertight.h"

namespace ra {
namespace {

template <class T>
std::optional<TriangleHit<T>> wt(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  return watertight::hit(r, a, b, c, false);
}

// A random triangle in [-1,1]^3 and a ray from [-4,4]^3 aimed at one of its
// points with barycentrics >= 0.1 (well inside), in float.
struct Shot {
  Rayf r;
  Vec3f a, b, c;
};
Shot random_shot(std::mt19937& g) {
  std::uniform_real_distribution<float> u1(-1, 1), u4(-4, 4), w(0.1f, 0.8f);
  Shot s;
  s.a = {u1(g), u1(g), u1(g)};
  s.b = {u1(g), u1(g), u1(g)};
  s.c = {u1(g), u1(g), u1(g)};
  const float b1 = w(g), b2 = std::min(w(g), 0.9f - b1);
  const Vec3f aim = s.a + (s.b - s.a) * b1 + (s.c - s.a) * b2;
  const Vec3f o{u4(g), u4(g), u4(g)};
  s.r = {o, aim - o};
  return s;
}

// Multiplying d by 2^k is exact in float and multiplies every quantity of the
// method by a power of two: Sx, Sy and the edge functions are unchanged, Sz,
// the scaled z's, t_scaled and t are multiplied by 2^-k. A bound with
// consistent units scales like t, so the verdict cannot change and t must be
// exactly t0 * 2^-k. (Before the fix, delta_x/delta_y added the scaled z to
// world-space x: with |d| ~ 1e-8 most of these hits were dropped.)
TEST(WatertightTBound, VerdictAndTDoNotDependOnDirectionLength) {
  std::mt19937 g(20240611);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Shot s = random_shot(g);
    const auto h0 = wt(s.r, s.a, s.b, s.c);
    hits += h0.has_value();
    for (int k : {-27, -13, 13}) {
      Rayf r = s.r;
      r.d = r.d * std::ldexp(1.0f, k);
      const auto h = wt(r, s.a, s.b, s.c);
      ASSERT_EQ(h0.has_value(), h.has_value()) << "case " << i << ", d scaled by 2^" << k;
      if (h) {
        EXPECT_EQ(h->t, std::ldexp(h0->t, -k)) << "case " << i << ", 2^" << k;
        EXPECT_EQ(h->b1, h0->b1);
        EXPECT_EQ(h->b2, h0->b2);
      }
    }
  }
  // Aimed well inside, from 1..8 units away: the bound (~1e-6 relative) keeps them all.
  EXPECT_EQ(hits, 2000);
}

// Scaling the whole scene (origin, direction, vertices) by 2^k is exact too:
// translated and sheared coordinates scale by 2^k, edge functions and det by
// 4^k, the scaled z's and t not at all; delta_e scales by 4^k and delta_t not
// at all. So a scene at ~1e-8 gets the verdicts and t of the same scene at 1.
TEST(WatertightTBound, SceneScaledToTenToTheMinusEightKeepsEveryVerdict) {
  std::mt19937 g(7);
  const float s = std::ldexp(1.0f, -27);  // 7.45e-9
  for (int i = 0; i < 2000; ++i) {
    const Shot x = random_shot(g);
    const Rayf r{x.r.o * s, x.r.d * s};
    const auto h0 = wt(x.r, x.a, x.b, x.c);
    const auto h = wt(r, x.a * s, x.b * s, x.c * s);
    ASSERT_EQ(h0.has_value(), h.has_value()) << "case " << i;
    if (h) {
      EXPECT_EQ(h->t, h0->t) << "case " << i;
    }
  }
}

// Regression: audit case scale:1e-08:4:0 (seed 1), a true hit at
// t = 0x1.19df498d87399p+0 by the exact oracle, which watertight/float missed:
// |d| ~ 4e-6 made delta_x = gamma(5) (max|x'| + max z') ~ 3.8e-7 against
// max|x'| ~ 3.6e-6, so delta_e (5.6e-12) ~ max|e| (6.0e-12) and delta_t = 1.86 > t.
TEST(WatertightTBound, Scale1em8Case4IsAHit) {
  const Rayf r{{0x1.988e58p-19f, 0x1.0fcda4p-16f, 0x1.58601p-18f},
               {-0x1.2d2026p-18f, -0x1.fc34e4p-17f, -0x1.62469ep-20f}};
  const Vec3f a{-0x1.6e398ep-18f, -0x1.7fa174p-19f, 0x1.4bc8f6p-18f};
  const Vec3f b{0x1.62947cp-19f, 0x1.7555d4p-19f, 0x1.124d0cp-26f};
  const Vec3f c{-0x1.5de40ap-20f, -0x1.426952p-23f, 0x1.1547a4p-18f};
  const auto h = wt(r, a, b, c);
  ASSERT_TRUE(h.has_value());
  EXPECT_NEAR(h->t, 0x1.19df498d87399p+0, 1e-5);
}

// A hit whose float arithmetic is exact is kept at any grazing angle: the
// triangle lies in z = 0, the ray d = (1, 1/2, th) meets it at t = 1 at an
// angle ~ th / 1.1. With kz = x, Sx = -1/2 and Sy = -th are exact, and so are
// all sheared coordinates (small dyadic numbers); the thin direction y' = th (1 - X)
// comes from the small z's, so delta_y ~ gamma(5) th (3.75) and delta_t ~ 8e-6.
// (pbrt-v4's form, gamma(5) (max|y'| + max z'), with max z' = 2.75, gives
// delta_t ~ 5.5e-6 / th: 5.8 at th = 2^-20, and dropped this hit.)
TEST(WatertightTBound, ExactlyComputedGrazingHitIsKept) {
  const float th = std::ldexp(1.0f, -20);
  const Vec3f a{-1, -1, 0}, b{2, -1, 0}, c{0.5f, 2, 0};
  const Vec3f p{0.25f, 0.25f, 0};
  const Rayf r{{p.x - 1, p.y - 0.5f, -th}, {1, 0.5f, th}};
  const auto h = wt(r, a, b, c);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->t, 1.0f);
}

// Conservative by design: the triangle lies in the plane z = x and the ray
// d = (1, 1/2, 1 + th) meets it at t = 1 at an angle ~ th / 2.1 (all inputs
// are exact floats, so the true answer is that hit). Now the thin direction of
// the sheared triangle, x' = X + Sx Z ~ th (Z - 1) (max ~ 1.75 th), is a
// difference of terms ~ 2.75 with Sx = -1/(1+th) rounded: the float edge
// functions really carry ~10% error at th = 2^-20. The bound: delta_x =
// gamma(5) (2.75 + 2.75) = 1.6e-6, delta_e ~ 2 delta_x max|y'| (2.125) = 7e-6,
// det ~ 9 th, delta_t >= 3 delta_e max z' (2.75) / det ~ 6.4e-6 / th.
// In float: th = 2^-10 -> delta_t ~ 6.6e-3 < 1, kept; th = 2^-20 -> ~6.7 > 1,
// dropped (a false miss). In double gamma is 2^29 times smaller: kept.
TEST(WatertightTBound, FloatDropsGrazingHitItCannotCertifyAndDoubleKeepsIt) {
  const auto shot = [](double th) {
    const Vec3d a{-1, -1, -1}, b{2, -1, 2}, c{0.5, 2, 0.5};
    const Vec3d p{0.25, 0.25, 0.25};
    const Vec3d d{1, 0.5, 1 + th};
    return std::tuple{Rayd{p - d, d}, a, b, c};
  };
  for (double th : {std::ldexp(1.0, -10), std::ldexp(1.0, -20)}) {
    const auto [r, a, b, c] = shot(th);
    const auto hd = wt(r, a, b, c);
    ASSERT_TRUE(hd.has_value()) << th;
    EXPECT_NEAR(hd->t, 1.0, 1e-12);
    const auto hf = wt(Rayf(r), Vec3f(a), Vec3f(b), Vec3f(c));
    EXPECT_EQ(hf.has_value(), th > 1e-4) << "float, th = " << th;
  }
}

}  // namespace
}  // namespace ra
