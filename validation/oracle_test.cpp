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

// ------------------------------------------- exact reference (rationals) ---
// An independent reference for the oracle, written as the textbook formulas in
// GMP rationals (mpq_class holds a double exactly) and MPFR: the plane crossing
// t = n.(A - o) / n.d with n = (B - A) x (C - A), the crossing point
// P = o + t d, and P's barycentric areas against n. It shares no code with the
// oracle, whose filters and exact path work with edge functions instead.
#include <gmpxx.h>
#include <mpfr.h>

#include "families.h"

namespace {

struct Q3 {
  mpq_class x, y, z;
};
Q3 q3(const Vec3d& v) { return {mpq_class(v.x), mpq_class(v.y), mpq_class(v.z)}; }
Q3 operator-(const Q3& a, const Q3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Q3 operator+(const Q3& a, const Q3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Q3 operator*(const Q3& a, const mpq_class& s) { return {a.x * s, a.y * s, a.z * s}; }
mpq_class qdot(const Q3& a, const Q3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Q3 qcross(const Q3& a, const Q3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// A rational rounded to the nearest double (ties to even), via MPFR.
double round_q(const mpq_class& v) {
  mpfr_t f;
  mpfr_init2(f, 53);
  mpfr_set_q(f, v.get_mpq_t(), MPFR_RNDN);
  const double d = mpfr_get_d(f, MPFR_RNDN);
  mpfr_clear(f);
  return d;
}

ra::oracle::Answer ref_triangle(const Rayd& r, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  ra::oracle::Answer ans;
  ans.t = ans.t_far = std::numeric_limits<double>::quiet_NaN();
  const Q3 o = q3(r.o), d = q3(r.d), A = q3(a), B = q3(b), C = q3(c);
  const Q3 n = qcross(B - A, C - A);
  if (qdot(n, n) == 0 || qdot(d, d) == 0) return ans.verdict = Verdict::degenerate, ans;
  const mpq_class den = qdot(n, d), num = qdot(n, A - o);
  if (den == 0) return ans.verdict = num == 0 ? Verdict::coplanar : Verdict::miss, ans;
  const mpq_class t = num / den;
  if (t < std::max(r.tmin, 0.0) || (std::isfinite(r.tmax) && t > r.tmax))
    return ans.verdict = Verdict::miss, ans;
  const Q3 P = o + d * t;
  const mpq_class l[3] = {qdot(n, qcross(C - B, P - B)), qdot(n, qcross(A - C, P - C)),
                          qdot(n, qcross(B - A, P - A))};
  int zeros = 0;
  for (const auto& x : l) {
    if (x < 0) return ans.verdict = Verdict::miss, ans;
    zeros += x == 0;
  }
  ans.verdict = zeros ? Verdict::boundary : Verdict::hit;
  ans.zero_edges = zeros;
  ans.t = round_q(t);
  return ans;
}

void expect_same(const ra::oracle::Answer& got, const ra::oracle::Answer& want) {
  EXPECT_EQ(ra::oracle::verdict_name(got.verdict), ra::oracle::verdict_name(want.verdict));
  if (want.verdict == Verdict::hit || want.verdict == Verdict::boundary) {
    EXPECT_EQ(got.t, want.t) << std::hexfloat << got.t << " vs " << want.t;
    if (want.verdict == Verdict::boundary) {
      EXPECT_EQ(got.zero_edges, want.zero_edges);
    }
  }
}

TEST(OracleReference, EveryTriangleFamilyAgreesWithRationals) {
  using namespace ra::audit;
  for (const Family& f : families()) {
    if (f.kind != ra::Kind::triangle) continue;
    for (Precision p : {Precision::f64, Precision::f32})
      for (int s = 0; s < int(f.sweep.size()); ++s) {
        TriangleBatch b;
        generate(f, s, p, stream_seed(11, f.name, s, 0), f.name == "closed-mesh" ? 8 : 40, b);
        for (const Probe& pr : b.probes)
          for (int k = pr.first; k < pr.first + pr.count; ++k) {
            SCOPED_TRACE(f.name + " sweep " + f.sweep[std::size_t(s)] + " " + precision_name(p) +
                         " triangle " + std::to_string(k));
            const Tri& t = b.tris[std::size_t(k)];
            expect_same(ra::oracle::triangle(pr.ray, t.a, t.b, t.c), ref_triangle(pr.ray, t.a, t.b, t.c));
          }
      }
  }
}

// Rays aimed at an exact point of an edge at large offsets: the edge function
// is exactly zero but no filter can certify a zero, so the exact path runs.
TEST(OracleReference, ExactEdgeHitsAtLargeOffsets) {
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double off : {0.0, 1e3, 1e5, 148376.0, 1e7}) {
    for (int i = 0; i < 50; ++i) {
      SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i));
      const Vec3d O{off, -off / 3, off / 7};
      // Coordinates on a 2^-20 grid so that midpoints and o - P are exact.
      auto grid = [&](double s) {
        return Vec3d{std::round(u(g) * s * 0x1p20) * 0x1p-20, std::round(u(g) * s * 0x1p20) * 0x1p-20,
                     std::round(u(g) * s * 0x1p20) * 0x1p-20};
      };
      const Vec3d a = O + grid(1), b = O + grid(1), c = O + grid(1);
      const Vec3d P = (a + b) * 0.5;  // exact: a + b is on a 2^-20 grid below 2^53 units
      const Vec3d o = P + grid(3);
      const Rayd r{o, P - o};
      ASSERT_EQ(P - o + o, P);  // the direction is exact
      const auto got = ra::oracle::triangle(r, a, b, c);
      const auto want = ref_triangle(r, a, b, c);
      expect_same(got, want);
      if (want.verdict == Verdict::boundary) {
        EXPECT_EQ(want.zero_edges, 1);
        EXPECT_EQ(got.t, 1.0);
      }
    }
  }
}

// Vertex hits at large offsets, with and without an exactly representable
// direction, all checked against the rationals.
TEST(OracleReference, VertexHitsAtLargeOffsets) {
  std::mt19937_64 g(6);
  std::uniform_real_distribution<double> u(-1, 1);
  int boundary = 0;
  for (double off : {0.0, 1.0, 1e4, 1e7, 3e7}) {
    for (int i = 0; i < 100; ++i) {
      SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i));
      const Vec3d O{off, off * 0.75, -off};
      const Vec3d v = O + Vec3d{u(g), u(g), u(g)};
      const Vec3d p = v + Vec3d{u(g), u(g), u(g)}, q = v + Vec3d{u(g), u(g), u(g)};
      const Vec3d o = v + Vec3d{u(g), u(g), u(g)} * 2.0;
      for (const Rayd& r : {Rayd{o, v - o}, Rayd{o, (v - o) * 3.0}}) {
        const auto want = ref_triangle(r, v, p, q);
        expect_same(ra::oracle::triangle(r, v, p, q), want);
        boundary += want.verdict == Verdict::boundary;
      }
    }
  }
  EXPECT_GT(boundary, 50);  // exact vertex hits did occur
}

// Near-boundary cases that the filters cannot decide: an exact point of an
// edge between full-mantissa endpoints far from the origin (the interval
// products are inexact, so no filter can certify the zero), and the points
// one and two ulps around it; compared against the rationals, with the
// exact fallback counted.
TEST(OracleReference, UlpsAroundAnEdgePointTakeTheExactPath) {
  std::mt19937_64 g(10);
  std::uniform_real_distribution<double> u(-1, 1);
  unsigned long long on_edge = 0, fallbacks = 0;
  for (double off : {1.0, 1e3, 1e6, 148376.0}) {
    for (int i = 0; i < 20; ++i) {
      const Vec3d P = Vec3d{off, -off / 3, off * 0.7} + Vec3d{u(g), u(g), u(g)};
      // a, b = P -+ h with h a multiple of ulp(P) so that P is exactly their midpoint.
      Vec3d h;
      for (int k = 0; k < 3; ++k) h[k] = std::ldexp(std::round(u(g) * 1024), std::ilogb(P[k]) - 52 + 30);
      const Vec3d a = P - h, b = P + h, c = P + Vec3d{u(g), u(g), u(g)};
      if (!(P - a == h && b - P == h)) continue;
      const Vec3d o = P + Vec3d{u(g), u(g), 2 + u(g)};
      const Vec3d d = P - o;
      if (!(o + d == P && P - d == o)) continue;  // want d exact
      for (int dx = -2; dx <= 2; ++dx) {
        Vec3d t = P;
        for (int k = 0; k < std::abs(dx); ++k) t.x = std::nextafter(t.x, dx > 0 ? 1e300 : -1e300);
        const Rayd r{o, t - o};
        SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i) + " ulps " + std::to_string(dx));
        const auto before = ra::oracle::exact_fallbacks();
        const auto want = ref_triangle(r, a, b, c);
        expect_same(ra::oracle::triangle(r, a, b, c), want);
        if (dx == 0) {
          EXPECT_EQ(want.verdict, Verdict::boundary);
          on_edge += 1;
          fallbacks += ra::oracle::exact_fallbacks() - before;
        }
      }
    }
  }
  EXPECT_GT(on_edge, 40u);
  EXPECT_EQ(fallbacks, on_edge);  // every exact edge hit needed the exact path
}

// ---------------------------------------------------- sphere reference ---
// |o + t d - c|^2 = r^2, i.e. A t^2 + 2 B t + C = 0 with A = d.d,
// B = d.(o - c), C = (o - c).(o - c) - r^2, solved as (-B -+ sqrt(B^2 - AC)) / A
// in 4096-bit MPFR and rounded to double; a double root -B / A is rational.
ra::oracle::Answer ref_sphere(const Rayd& r, const Vec3d& center, double radius) {
  ra::oracle::Answer ans;
  ans.t = ans.t_far = std::numeric_limits<double>::quiet_NaN();
  const Q3 d = q3(r.d), f = q3(r.o) - q3(center);
  const mpq_class A = qdot(d, d), B = qdot(d, f), C = qdot(f, f) - mpq_class(radius) * mpq_class(radius);
  const mpq_class disc = B * B - A * C;
  const double lo = std::max(r.tmin, 0.0), hi = r.tmax;
  ans.verdict = Verdict::miss;
  if (disc < 0) return ans;
  if (disc == 0) {
    const mpq_class t = -B / A;
    if (t >= lo && (!std::isfinite(hi) || t <= hi)) ans.verdict = Verdict::boundary, ans.t = round_q(t);
    return ans;
  }
  mpfr_t s, t1, t2, tmp;
  mpfr_inits2(4096, s, t1, t2, tmp, static_cast<mpfr_ptr>(nullptr));
  mpfr_set_q(s, disc.get_mpq_t(), MPFR_RNDN);
  mpfr_sqrt(s, s, MPFR_RNDN);
  const mpq_class mB = -B;
  mpfr_set_q(tmp, mB.get_mpq_t(), MPFR_RNDN);
  mpfr_sub(t1, tmp, s, MPFR_RNDN), mpfr_add(t2, tmp, s, MPFR_RNDN);
  mpfr_set_q(tmp, A.get_mpq_t(), MPFR_RNDN);
  mpfr_div(t1, t1, tmp, MPFR_RNDN), mpfr_div(t2, t2, tmp, MPFR_RNDN);
  auto in = [&](mpfr_t t) {
    return mpfr_cmp_d(t, lo) >= 0 && (!std::isfinite(hi) || mpfr_cmp_d(t, hi) <= 0);
  };
  const bool near_in = in(t1), far_in = in(t2);
  const double n = mpfr_get_d(t1, MPFR_RNDN), fa = mpfr_get_d(t2, MPFR_RNDN);
  mpfr_clears(s, t1, t2, tmp, static_cast<mpfr_ptr>(nullptr));
  if (!near_in && !far_in) return ans;
  ans.verdict = Verdict::hit;
  ans.t = near_in ? n : fa;
  if (near_in && far_in) ans.t_far = fa;
  return ans;
}

void expect_same_sphere(const ra::oracle::Answer& got, const ra::oracle::Answer& want) {
  expect_same(got, want);
  if (std::isnan(want.t_far)) EXPECT_TRUE(std::isnan(got.t_far));
  else EXPECT_EQ(got.t_far, want.t_far);
}

TEST(OracleReference, EverySphereFamilyAgreesWithRationals) {
  using namespace ra::audit;
  for (const Family& f : families()) {
    if (f.kind != ra::Kind::sphere) continue;
    for (Precision p : {Precision::f64, Precision::f32})
      for (int s = 0; s < int(f.sweep.size()); ++s) {
        std::vector<SphereCase> cs;
        generate(f, s, p, stream_seed(11, f.name, s, 0), 60, cs);
        for (std::size_t i = 0; i < cs.size(); ++i) {
          SCOPED_TRACE(f.name + " sweep " + f.sweep[std::size_t(s)] + " case " + std::to_string(i));
          expect_same_sphere(ra::oracle::sphere(cs[i].ray, cs[i].center, cs[i].radius),
                             ref_sphere(cs[i].ray, cs[i].center, cs[i].radius));
        }
      }
  }
}

// Tangent rays (a double root, exactly) at many offsets and scales: the
// filters cannot certify a zero discriminant, so the exact path decides.
TEST(OracleReference, TangentRaysAreBoundaryWithExactT) {
  std::mt19937_64 g(8);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto before = ra::oracle::exact_fallbacks();
  for (double off : {0.0, 1e3, 1e6}) {
    for (int i = 0; i < 40; ++i) {
      const double R = std::ldexp(1.0, int(u(g) * 10));
      const Vec3d c{off + std::round(u(g) * 1024) / 64, std::round(u(g) * 1024) / 64, -off};
      // A ray along z passing at distance exactly R from the centre in x.
      const Rayd r{c + Vec3d{R, 0, -R * (3 + std::round(std::abs(u(g)) * 64) / 8)}, {0, 0, std::ldexp(1.0, int(u(g) * 4))}};
      SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i));
      const auto want = ref_sphere(r, c, R);
      ASSERT_EQ(want.verdict, Verdict::boundary);
      expect_same_sphere(ra::oracle::sphere(r, c, R), want);
    }
  }
  EXPECT_GE(ra::oracle::exact_fallbacks() - before, 120u);
}

// Two roots ahead, near-tangent (one ulp off) and from inside, at offsets:
// both t and t_far against the 4096-bit reference.
TEST(OracleReference, TwoRootAndNearTangentRays) {
  std::mt19937_64 g(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double off : {0.0, 1e2, 1e5, 1e7}) {
    for (int i = 0; i < 60; ++i) {
      const double R = 0.5 + u(g) * 0.25 + 1;
      const Vec3d c{off + u(g), u(g), off * 0.5 + u(g)};
      const Vec3d aim = c + Vec3d{u(g), u(g), u(g)} * R;
      const Vec3d o = i % 3 == 0 ? c + Vec3d{u(g), u(g), u(g)} * (R * 0.5) : aim + Vec3d{u(g), u(g), 3 + u(g)} * R;
      const Rayd r{o, aim - o};
      SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i));
      expect_same_sphere(ra::oracle::sphere(r, c, R), ref_sphere(r, c, R));
      // Tangent from the side, nudged by one ulp in and out.
      for (double dx : {-1.0, 0.0, 1.0}) {
        double x = c.x + R;
        if (dx != 0) x = std::nextafter(x, dx * 1e300);
        const Rayd t{{x, c.y, c.z - 4 * R}, {0, 0, 1}};
        expect_same_sphere(ra::oracle::sphere(t, c, R), ref_sphere(t, c, R));
      }
    }
  }
}

}  // namespace
