// Tests of the exact oracle (validation/oracle.h) against hand-made cases
// whose answers follow from the geometry, and against a plain double solver where it is far from any boundary.
#include "oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "methods/moller.h"

namespace {

using ra::Rayd;
using ra::Vec3d;
using ra::oracle::Verdict;

const Vec3d A{0, 0, 0}, B{1, 0, 0}, C{0, 1, 0};  // the unit right triangle in z = 0

ra::oracle::Answer tri(const Vec3d& o, const Vec3d& d, double tmin = 0,
                       double tmax = std::numeric_limits<double>::infinity()) {
  return ra::oracle::triangle(Rayd{o, d, tmin, tmax}, A, B, C);
}

TEST(OracleTriangle, InteriorHitHasExactT) {
  const auto a = tri({0.25, 0.25, 1}, {0, 0, -1});
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 1.0);
}

TEST(OracleTriangle, TIsCorrectlyRounded) {
  const auto a = tri({0.25, 0.25, 1}, {0, 0, -3});
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 1.0 / 3.0);  // 1/3 rounded to nearest is what IEEE division gives
}

TEST(OracleTriangle, ExactEdgeHitsAreBoundary) {
  for (const Vec3d& p : {Vec3d{0.5, 0, 0}, Vec3d{0, 0.375, 0}, Vec3d{0.5, 0.5, 0}}) {
    const Vec3d o = p + Vec3d{0.125, 0.25, 1};
    const auto a = tri(o, p - o);
    EXPECT_EQ(a.verdict, Verdict::boundary) << p;
    EXPECT_EQ(a.zero_edges, 1) << p;
    EXPECT_EQ(a.t, 1.0);
  }
}

TEST(OracleTriangle, ExactVertexHitsAreBoundary) {
  for (const Vec3d& v : {A, B, C}) {
    const Vec3d o = v + Vec3d{1, 2, 3};
    const auto a = tri(o, v - o);
    EXPECT_EQ(a.verdict, Verdict::boundary) << v;
    EXPECT_EQ(a.zero_edges, 2) << v;
    EXPECT_EQ(a.t, 1.0);
  }
}

TEST(OracleTriangle, OneUlpOutsideAnEdgeIsAMiss) {
  const double y = -std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(tri({0.5, y, 1}, {0, 0, -1}).verdict, Verdict::miss);
  const double x = std::nextafter(0.5, 1.0);  // just beyond the hypotenuse x + y = 1
  EXPECT_EQ(tri({x, 0.5, 1}, {0, 0, -1}).verdict, Verdict::miss);
  EXPECT_EQ(tri({std::nextafter(0.5, 0.0), 0.5, 1}, {0, 0, -1}).verdict, Verdict::hit);
}

TEST(OracleTriangle, MissesAndBehindOrigin) {
  EXPECT_EQ(tri({1, 1, 1}, {0, 0, -1}).verdict, Verdict::miss);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, 1}).verdict, Verdict::miss);  // triangle behind
  EXPECT_TRUE(std::isnan(tri({1, 1, 1}, {0, 0, -1}).t));
}

TEST(OracleTriangle, WindowIsClosed) {
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, -1}, 0, 1).verdict, Verdict::hit);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, -1}, 0, std::nextafter(1.0, 0.0)).verdict, Verdict::miss);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, -1}, 1, 2).verdict, Verdict::hit);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, -1}, std::nextafter(1.0, 2.0), 2).verdict, Verdict::miss);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, -1}, 2, 1).verdict, Verdict::miss);  // empty window
}

TEST(OracleTriangle, OriginInThePlaneHitsAtZero) {
  const auto a = tri({0.25, 0.25, 0}, {0.1, 0.2, -1});
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 0.0);
  // A negative tmin does not extend the ray backwards.
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, 1}, -5, 5).verdict, Verdict::miss);
}

TEST(OracleTriangle, CoplanarAndParallel) {
  EXPECT_EQ(tri({-1, 0.25, 0}, {1, 0, 0}).verdict, Verdict::coplanar);
  EXPECT_EQ(tri({5, 5, 0}, {1, 0, 0}).verdict, Verdict::coplanar);  // in the plane, away from it
  EXPECT_EQ(tri({-1, 0.25, 1}, {1, 0, 0}).verdict, Verdict::miss);  // parallel, off the plane
  // In the plane only by a tiny z: still a plain miss/hit question, not coplanar.
  EXPECT_EQ(tri({-1, 0.25, 1e-300}, {1, 0, 0}).verdict, Verdict::miss);
}

TEST(OracleTriangle, Degenerate) {
  const Rayd r{{0.25, 0.25, 1}, {0, 0, -1}};
  EXPECT_EQ(ra::oracle::triangle(r, A, B, Vec3d{2, 0, 0}).verdict, Verdict::degenerate);
  EXPECT_EQ(ra::oracle::triangle(r, A, B, A).verdict, Verdict::degenerate);
  EXPECT_EQ(ra::oracle::triangle(r, A, {1, 1, 1}, {0.5, 0.5, 0.5}).verdict, Verdict::degenerate);
  EXPECT_EQ(tri({0.25, 0.25, 1}, {0, 0, 0}).verdict, Verdict::degenerate);
  EXPECT_EQ(tri({NAN, 0.25, 1}, {0, 0, -1}).verdict, Verdict::degenerate);
  // Collinear up to a rounding of 0.1 * 3: exactly not collinear, so judged.
  EXPECT_NE(ra::oracle::triangle(r, A, {0.1, 0.1, 0}, {0.1 * 3, 0.3, 0}).verdict, Verdict::degenerate);
}

TEST(OracleTriangle, ExactFarFromOriginEdge) {
  // Embree's placement: the edge point is exact, so the answer must be boundary.
  const Vec3d off{148376, 1234, -223423};
  const Rayd r{off + Vec3d{0.5, 0, 1}, {0, 0, -1}};
  const auto a = ra::oracle::triangle(r, A + off, B + off, C + off);
  EXPECT_EQ(a.verdict, Verdict::boundary);
  EXPECT_EQ(a.t, 1.0);
}

TEST(OracleTriangle, AgreesWithDoubleSolverFarFromBoundaries) {
  std::mt19937_64 g(42);  // seed printed by the failure message via SCOPED_TRACE
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    SCOPED_TRACE("seed 42, case " + std::to_string(i));
    const Vec3d a{u(g), u(g), u(g)}, b{u(g), u(g), u(g)}, c{u(g), u(g), u(g)};
    const Rayd r{{4 * u(g), 4 * u(g), 4 * u(g)}, {u(g), u(g), u(g)}};
    const auto h = ra::moller::hit(r, a, b, c, false);
    const auto o = ra::oracle::triangle(r, a, b, c);
    // Only where the double answer is far (1e-6) from every decision boundary.
    const Vec3d n = cross(b - a, c - a);
    if (std::abs(dot(n, r.d)) < 1e-3 * length(n) * length(r.d)) continue;
    if (h) {
      if (h->b1 < 1e-6 || h->b2 < 1e-6 || h->b1 + h->b2 > 1 - 1e-6 || h->t < 1e-6) continue;
      ++checked;
      ASSERT_EQ(o.verdict, Verdict::hit);
      EXPECT_NEAR(o.t, h->t, 1e-9 * std::abs(o.t));
    } else {
      // Re-solve without the window to see how far from the boundaries it is.
      const auto line = ra::moller::hit(Rayd{r.o, r.d, -1e300, 1e300}, a, b, c, false);
      if (line && std::abs(line->t) < 1e-6) continue;
      ++checked;
      EXPECT_EQ(o.verdict, Verdict::miss);
    }
  }
  EXPECT_GT(checked, 10000);
}

// ------------------------------------------------------------- sphere ---
ra::oracle::Answer sph(const Vec3d& o, const Vec3d& d, double r = 1, double tmin = 0) {
  return ra::oracle::sphere(Rayd{o, d, tmin}, {0, 0, 0}, r);
}

TEST(OracleSphere, TwoRootsAhead) {
  const auto a = sph({0, 0, -5}, {0, 0, 1});
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 4.0);
  EXPECT_EQ(a.t_far, 6.0);
}

TEST(OracleSphere, InsideGetsTheFarRootOnly) {
  const auto a = sph({0, 0, 0}, {0, 0, 2});
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 0.5);
  EXPECT_TRUE(std::isnan(a.t_far));
}

TEST(OracleSphere, TangentIsBoundary) {
  const auto a = sph({1, 0, -5}, {0, 0, 1});
  EXPECT_EQ(a.verdict, Verdict::boundary);
  EXPECT_EQ(a.t, 5.0);
  EXPECT_EQ(sph({std::nextafter(1.0, 2.0), 0, -5}, {0, 0, 1}).verdict, Verdict::miss);
}

TEST(OracleSphere, MissBehindAndDegenerate) {
  EXPECT_EQ(sph({2, 0, -5}, {0, 0, 1}).verdict, Verdict::miss);
  EXPECT_EQ(sph({0, 0, 5}, {0, 0, 1}).verdict, Verdict::miss);
  EXPECT_EQ(sph({0, 0, -5}, {0, 0, 1}, 0).verdict, Verdict::degenerate);
  EXPECT_EQ(sph({0, 0, -5}, {0, 0, 0}).verdict, Verdict::degenerate);
  // A window starting past the near root gives the far one.
  EXPECT_EQ(sph({0, 0, -5}, {0, 0, 1}, 1, 4.5).t, 6.0);
}

TEST(OracleSphere, IrrationalRootWithinHalfAnUlp) {
  const auto a = sph({0.5, 0, -5}, {0, 0, 1});
  ASSERT_EQ(a.verdict, Verdict::hit);
  const long double exact = 5.0L - std::sqrt(0.75L);
  // t is in [4, 8): one ulp is 2^-50, so correct rounding is within 2^-51.
  EXPECT_LE(std::abs((long double)a.t - exact), std::ldexp(1.0L, -51));
}

TEST(OracleSphere, HugeSphereAsFloor) {
  // A radius-1e7 floor touching y = 0, seen from y = 1 straight down: t = 1.
  const auto a = ra::oracle::sphere(Rayd{{0, 1, 0}, {0, -1, 0}}, {0, -1e7, 0}, 1e7);
  EXPECT_EQ(a.verdict, Verdict::hit);
  EXPECT_EQ(a.t, 1.0);
}

}  // namespace
