// Tests of the exact oracle (validation/exact/oracle.h) against hand-made cases
// whose answers follow from the geometry, and against a plain double solver where it is far from any boundary.
#include "oracle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <utility>
#include <random>
#include <vector>

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
Q3 qcross(const Q3& a, const Q3& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// A rational rounded to the nearest double (ties to even), subnormals
// included, in integers: q = floor(|v| 2^k) with 2^52 <= q < 2^53 (k at most
// 1074, the subnormal grid), then q or q + 1 by the remainder. (Rounding to
// 53 bits in MPFR and then to a subnormal double would round twice.)
double round_q(const mpq_class& v) {
  if (sgn(v) == 0) return 0;
  const mpz_class num = abs(v.get_num()), den = v.get_den();
  long k = 52 - (long(mpz_sizeinbase(num.get_mpz_t(), 2)) - long(mpz_sizeinbase(den.get_mpz_t(), 2)));
  const mpz_class lo = mpz_class(1) << 52, hi = mpz_class(1) << 53;
  mpz_class q, r, dk;
  for (;;) {
    k = std::min(k, 1074L);
    mpz_class nk = num;
    dk = den;
    if (k >= 0)
      nk <<= k;
    else
      dk <<= -k;
    mpz_fdiv_qr(q.get_mpz_t(), r.get_mpz_t(), nk.get_mpz_t(), dk.get_mpz_t());
    if (q >= hi)
      --k;
    else if (q < lo && k < 1074)
      ++k;
    else
      break;
  }
  const int c = cmp(mpz_class(2 * r), dk);
  if (c > 0 || (c == 0 && mpz_odd_p(q.get_mpz_t()))) ++q;
  const double x = std::ldexp(q.get_d(), int(-k));  // q <= 2^53: exact (inf past DBL_MAX)
  return sgn(v) < 0 ? -x : x;
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
  if (t < std::max(r.tmin, 0.0) || (std::isfinite(r.tmax) && t > r.tmax)) return ans.verdict = Verdict::miss, ans;
  const Q3 P = o + d * t;
  const mpq_class l[3] = {qdot(n, qcross(C - B, P - B)), qdot(n, qcross(A - C, P - C)), qdot(n, qcross(B - A, P - A))};
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
            SCOPED_TRACE(f.name + " sweep " + f.sweep[std::size_t(s)] + " " + precision_name(p) + " triangle " +
                         std::to_string(k));
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
      EXPECT_EQ(want.verdict, Verdict::boundary);  // aimed at the exact midpoint of edge ab
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
// one and two ulps around it; compared against the rationals. With the ray
// as built, the doubles of each edge function share a grid of at most 61
// bits and the 256-bit determinant settles every exact edge hit without
// GMP; with d scaled by 2^40 (the same rays: t scales by 2^-40) they span
// more and every exact edge hit takes the GMP path. Both are checked.
TEST(OracleReference, UlpsAroundAnEdgePointTakeTheExactPath) {
  for (const double scale : {1.0, 0x1p40}) {
    SCOPED_TRACE("d scaled by " + std::to_string(scale));
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
          const Rayd r{o, (t - o) * scale};
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
    EXPECT_EQ(fallbacks, scale == 1.0 ? 0u : on_edge);
  }
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
  auto in = [&](mpfr_t t) { return mpfr_cmp_d(t, lo) >= 0 && (!std::isfinite(hi) || mpfr_cmp_d(t, hi) <= 0); };
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
  if (std::isnan(want.t_far))
    EXPECT_TRUE(std::isnan(got.t_far));
  else
    EXPECT_EQ(got.t_far, want.t_far);
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
      const Rayd r{c + Vec3d{R, 0, -R * (3 + std::round(std::abs(u(g)) * 64) / 8)},
                   {0, 0, std::ldexp(1.0, int(u(g) * 4))}};
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

// ------------------------------------------- double-double filter attacks ---
// The oracle's second filter (oracle.cpp, "double-double") evaluates signs and
// t in about 106 bits with error bounds. These cases aim at it: the exact value
// is 0, or nonzero but below double-double's resolution (a tiny component
// added to a direction that was exactly 0 in that coordinate), or t is on or
// next to a midpoint between doubles or a double; the other inputs have full 53-bit
// mantissas so that the double-double arithmetic does round. Every answer is
// checked against the rationals. A bound below the true error shows up as a
// wrong verdict or a t one ulp off; the sweeps also check that both outcomes of
// the filter (decided, or handed to GMP) occur, so they straddle its limit.

// x + k ulps of x (rounded; any double is a fair input).
double ulps(double x, double k) { return x + k * std::ldexp(1.0, std::ilogb(x) - 52); }
bool exact_sum(double x, double y, double s) { return mpq_class(x) + mpq_class(y) == mpq_class(s); }
bool exact_sum(const Vec3d& x, const Vec3d& y, const Vec3d& s) {
  return exact_sum(x.x, y.x, s.x) && exact_sum(x.y, y.y, s.y) && exact_sum(x.z, y.z, s.z);
}
// 2^-k times the largest component of v.
double tiny_of(const Vec3d& v, int k) {
  return std::ldexp(1.0, std::ilogb(std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)})) - k);
}
constexpr int kBelow[] = {30, 60, 80, 90, 94, 97, 100, 102, 104, 106, 108, 111, 115, 130, 300};

struct TriCase {
  Rayd r;
  Vec3d a, b, c;
};
struct SphCase {
  Rayd r;
  Vec3d c;
  double radius;
};

// Exponent of the lowest set bit of x (x != 0).
int low_bit(double x) {
  int e;
  const auto m = static_cast<std::int64_t>(std::ldexp(std::frexp(x, &e), 53));
  return e - 53 + __builtin_ctzll(static_cast<unsigned long long>(std::abs(m)));
}
// The power of two that makes every (nonzero) value a multiple of 2^-100 while
// keeping it below 2^top, or 0 when there is none. The double-double filter
// only takes inputs whose products stay in double's exponent range (its range
// guard); tiny perturbations would otherwise go straight to GMP unseen, and
// scaling every input alike changes neither t nor the verdict.
int fit_scale(std::initializer_list<double> xs, int top) {
  int lo = 100000, hi = -100000;
  for (double x : xs)
    if (x != 0) lo = std::min(lo, low_bit(x)), hi = std::max(hi, std::ilogb(x) + 1);
  const int s = -100 - lo;
  return lo < 100000 && s > 0 && hi + s <= top ? s : 0;
}
Vec3d scale(const Vec3d& v, int s) { return {std::ldexp(v.x, s), std::ldexp(v.y, s), std::ldexp(v.z, s)}; }

// Checks one triangle query against the rationals, scaled into the
// double-double filter's range (and as given, when that differs); counts
// whether the filters decided the scaled query or GMP did.
void check_tri(const TriCase& k, int& decided, int& fell_back) {
  const auto want = ref_triangle(k.r, k.a, k.b, k.c);
  const int s = fit_scale({k.r.o.x, k.r.o.y, k.r.o.z, k.r.d.x, k.r.d.y, k.r.d.z, k.a.x, k.a.y, k.a.z, k.b.x, k.b.y,
                           k.b.z, k.c.x, k.c.y, k.c.z},
                          310);
  const Rayd r{scale(k.r.o, s), scale(k.r.d, s), k.r.tmin, k.r.tmax};
  const auto before = ra::oracle::exact_fallbacks();
  const auto got = ra::oracle::triangle(r, scale(k.a, s), scale(k.b, s), scale(k.c, s));
  (ra::oracle::exact_fallbacks() == before ? decided : fell_back) += 1;
  SCOPED_TRACE("scaled by 2^" + std::to_string(s));
  expect_same(got, want);
  if (s != 0) expect_same(ra::oracle::triangle(k.r, k.a, k.b, k.c), want);
}
void check_sph(const SphCase& k, int& decided, int& fell_back) {
  const auto want = ref_sphere(k.r, k.c, k.radius);
  const int s = fit_scale({k.r.o.x, k.r.o.y, k.r.o.z, k.r.d.x, k.r.d.y, k.r.d.z, k.c.x, k.c.y, k.c.z, k.radius}, 230);
  const Rayd r{scale(k.r.o, s), scale(k.r.d, s), k.r.tmin, k.r.tmax};
  const auto before = ra::oracle::exact_fallbacks();
  const auto got = ra::oracle::sphere(r, scale(k.c, s), std::ldexp(k.radius, s));
  (ra::oracle::exact_fallbacks() == before ? decided : fell_back) += 1;
  SCOPED_TRACE("scaled by 2^" + std::to_string(s));
  expect_same_sphere(got, want);
  if (s != 0) expect_same_sphere(ra::oracle::sphere(k.r, k.c, k.radius), want);
}

// Windows that end at the rounded crossing t or one ulp either side of it (the
// exact crossing is never a double here, so each is a clear hit or miss that
// only the sign of N - x D, or of root - x, decides).
std::vector<std::pair<double, double>> windows_around(double t);

// Checks k with its ray's window set to each of windows_around(t).
template <class Case, class Check>
void check_windows(const Case& k, double t, Check check) {
  for (const auto& [lo, hi] : windows_around(t)) {
    Case w = k;
    w.r.tmin = lo, w.r.tmax = hi;
    check(w);
  }
}

std::vector<std::pair<double, double>> windows_around(double t) {
  const double inf = std::numeric_limits<double>::infinity();
  const double below = std::nextafter(t, -inf), above = std::nextafter(t, inf);
  return {{0, below}, {0, t}, {0, above}, {below, inf}, {t, inf}, {above, inf}};
}

// Rays aimed exactly at the midpoint P of an edge (or at a vertex P) with
// d.z == 0 exactly, from full-mantissa points at offset `off` and size `sz`;
// `tilt` then sets d.z to +-2^-k |d| for every k in kBelow, which moves the
// edge functions through P by about 2^-k of their permanent: from far above
// double-double's resolution (2^-100 or so) to far below it.
std::vector<TriCase> edge_and_vertex_cases(std::mt19937_64& g, double off, double sz, bool tilt) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<TriCase> out;
  const Vec3d O{off, -off / 3, off * 0.7};
  const Vec3d P = O + Vec3d{u(g), u(g), u(g)} * sz;
  Vec3d h;  // a multiple of ulp(P): P -+ h are exact and P is their midpoint
  for (int k = 0; k < 3; ++k) h[k] = std::ldexp(std::round(u(g) * 1024), std::ilogb(P[k]) - 52 + 30);
  const Vec3d a = P - h, b = P + h, c = P + Vec3d{u(g), u(g), u(g)} * sz;
  const Vec3d o{P.x + 2 * sz * u(g), P.y + 2 * sz * u(g), P.z};
  const Vec3d d{P.x - o.x, P.y - o.y, 0};
  if (!exact_sum(a, h, P) || !exact_sum(P, h, b) || !exact_sum(o, d, P)) return out;
  for (const TriCase& t : {TriCase{Rayd{o, d}, a, b, c}, TriCase{Rayd{o, d}, P, b, c}}) {
    out.push_back(t);
    if (!tilt) continue;
    for (int k : kBelow)
      for (double sgn : {-1.0, 1.0}) {
        TriCase v = t;
        v.r.d.z = sgn * tiny_of(d, k);
        out.push_back(v);
      }
  }
  return out;
}

TEST(OracleDD, EdgeAndVertexFunctionsBelowDoubleDoubleResolution) {
  std::mt19937_64 g(21);
  int decided = 0, fell_back = 0, exact_zero = 0;
  for (double off : {0.0, 3.0, 1e3, 148376.0, 1e7})
    for (double sz : {1e-6, 1.0, 1e3})
      for (int i = 0; i < 10; ++i) {
        const auto cases = edge_and_vertex_cases(g, off, sz, true);
        for (std::size_t j = 0; j < cases.size(); ++j) {
          SCOPED_TRACE("offset " + std::to_string(off) + " size " + std::to_string(sz) + " case " + std::to_string(i) +
                       " variant " + std::to_string(j));
          check_tri(cases[j], decided, fell_back);
          exact_zero += cases[j].r.d.z == 0;
        }
      }
  EXPECT_GT(exact_zero, 200);
  EXPECT_GT(decided, 1000);    // the filters settled the larger tilts...
  EXPECT_GT(fell_back, 1000);  // ...and left the smaller ones to GMP
}

// A ray parallel to the plane (d = B - A, exactly, with d.z == 0), from off the
// plane or from a point of edge CA (coplanar), then tilted by 2^-k: the
// denominator n.d goes from exactly 0 to below and above resolution.
TEST(OracleDD, NearParallelAndNearCoplanarRays) {
  std::mt19937_64 g(22);
  std::uniform_real_distribution<double> u(-1, 1);
  int decided = 0, fell_back = 0, coplanar = 0;
  for (double off : {0.0, 1e3, 1e7})
    for (int i = 0; i < 30; ++i) {
      const double sz = std::ldexp(1.0, int(g() % 20) - 10);
      const Vec3d Q = Vec3d{off, off / 3, -off} + Vec3d{u(g), u(g), u(g)} * sz;
      Vec3d h;
      for (int k = 0; k < 3; ++k) h[k] = std::ldexp(std::round(u(g) * 0x1p20), std::ilogb(Q[k]) - 52 + 30);
      const Vec3d a = Q - h, c = Q + h;  // Q is the midpoint of CA
      const Vec3d b{a.x + sz * u(g), a.y + sz * u(g), a.z};
      const Vec3d d{b.x - a.x, b.y - a.y, 0};
      if (!exact_sum(a, h, Q) || !exact_sum(Q, h, c) || !exact_sum(a, d, b)) continue;
      const Vec3d off_plane = Q + Vec3d{u(g), u(g), u(g)} * sz;
      for (const Vec3d& o : {Q, off_plane, Vec3d{Q.x, Q.y, ulps(Q.z, 1)}, Vec3d{ulps(Q.x, -3), Q.y, Q.z}}) {
        for (int k = -1; k < int(std::size(kBelow)); ++k)
          for (double sgn : {-1.0, 1.0}) {
            if (k < 0 && sgn < 0) continue;
            const Vec3d dk{d.x, d.y, k < 0 ? 0.0 : sgn * tiny_of(d, kBelow[k])};
            SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i) + " tilt 2^-" +
                         std::to_string(k < 0 ? 0 : kBelow[k]));
            const TriCase t{Rayd{o, dk}, a, b, c};
            check_tri(t, decided, fell_back);
            coplanar += ref_triangle(t.r, a, b, c).verdict == Verdict::coplanar;
          }
      }
    }
  EXPECT_GT(coplanar, 50);
  EXPECT_GT(decided, 500);
  EXPECT_GT(fell_back, 500);
}

// t = m exactly, m a midpoint between two doubles (54 significant bits), so
// the answer is m rounded to even, or m a double; then t pushed off m by about
// 2^-75 .. 2^-110 relative (the origin, which is tiny, moved by 2^-j |P|), and
// for m a double, windows ending at m or next to it. The
// triangle has its centroid P = o + m d, all inputs exact and the differences
// A - o etc. about 80 bits wide, so double-double rounds throughout.
mpq_class ldexp_q(mpq_class x, int e) {
  if (e >= 0)
    mpq_mul_2exp(x.get_mpq_t(), x.get_mpq_t(), mp_bitcnt_t(e));
  else
    mpq_div_2exp(x.get_mpq_t(), x.get_mpq_t(), mp_bitcnt_t(-e));
  return x;
}

TEST(OracleDD, TriangleTOnAndNextToAMidpointOrADouble) {
  std::mt19937_64 g(23);
  std::uniform_real_distribution<double> u(-1, 1);
  int ties = 0, decided = 0, fell_back = 0;
  for (int i = 0; i < 150; ++i) {
    const int em = int(g() % 16) - 6;
    // Odd cases: M even, so m is a double and the crossing is exactly on it.
    const bool on_double = i % 2 == 1;
    const std::uint64_t M =
        ((std::uint64_t(1) << 53) | (g() & ((std::uint64_t(1) << 53) - 1)) | 1) - (on_double ? 1 : 0);
    const mpq_class m = ldexp_q(mpq_class(mpz_class(static_cast<unsigned long>(M))), em - 53);
    Vec3d d, P, o, e1, e2;
    bool exact = true;
    for (int k = 0; k < 3; ++k) {
      d[k] = std::ldexp(std::round(u(g) * 0x1p29), int(g() % 7) - 32);  // 30 bits
      const mpq_class md = m * mpq_class(d[k]);
      P[k] = round_q(md);
      const mpq_class ok = mpq_class(P[k]) - md;
      o[k] = ok.get_d();
      exact = exact && d[k] != 0 && P[k] != 0 && mpq_class(o[k]) == ok;
    }
    if (!exact) continue;
    for (int k = 0; k < 3; ++k) {
      e1[k] = std::ldexp(std::round(u(g) * 0x1p40), std::ilogb(P[k]) - 52 + 10);
      e2[k] = std::ldexp(std::round(u(g) * 0x1p40), std::ilogb(P[k]) - 52 + 10);
    }
    const Vec3d a = P + e1, b = P + e2, c = P - e1 - e2;
    if (!exact_sum(P, e1, a) || !exact_sum(P, e2, b) || !exact_sum(c, e1 + e2, P) || !exact_sum(e1, e2, e1 + e2))
      continue;
    SCOPED_TRACE("case " + std::to_string(i));
    const TriCase base{Rayd{o, d}, a, b, c};
    const auto want = ref_triangle(base.r, a, b, c);
    if (want.verdict != Verdict::hit) continue;  // a sliver seen edge-on
    ASSERT_EQ(want.t, round_q(m));
    ties += !on_double;
    check_tri(base, decided, fell_back);
    for (int k = 0; k < 3; ++k)
      for (int j : {75, 80, 85, 88, 91, 94, 97, 100, 103, 106, 110})
        for (double sgn : {-1.0, 1.0}) {
          TriCase v = base;
          v.r.o[k] = o[k] + sgn * tiny_of(P, j);
          SCOPED_TRACE("o[" + std::to_string(k) + "] moved by 2^-" + std::to_string(j) + " |P|");
          check_tri(v, decided, fell_back);
          if (on_double && k == 0 && (j == 94 || j == 100 || j == 106)) {
            check_windows(v, ref_triangle(v.r, a, b, c).t, [&](const TriCase& w) { check_tri(w, decided, fell_back); });
          }
        }
  }
  EXPECT_GT(ties, 50);
  EXPECT_GT(decided, 1000);
  EXPECT_GT(fell_back, 1000);
}

// Tangent rays from full-mantissa points (o.x = c.x + R and o.y = c.y exactly,
// d along z), then d.x or d.y set to +-2^-k |d|: the discriminant goes from
// exactly 0 to below and above resolution (d.x opens two roots or a miss by
// its sign, d.y always misses).
std::vector<SphCase> near_tangent_cases(std::mt19937_64& g, double off, bool tilt) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<SphCase> out;
  const double sz = std::ldexp(1.0, int(g() % 24) - 12);
  const Vec3d c = Vec3d{off, -off, off / 7} + Vec3d{u(g), u(g), u(g)} * sz;
  const double ulp = std::ldexp(1.0, std::ilogb(c.x) - 52);  // R on c.x's grid: c.x + R is exact
  const double R = std::round(sz * (0.5 + std::abs(u(g))) / ulp) * ulp;
  const Vec3d o{c.x + R, c.y, c.z + sz * (2 + u(g))};
  if (!exact_sum(c.x, R, o.x)) return out;
  const Vec3d d{0, 0, -std::ldexp(1 + std::abs(u(g)), int(g() % 8) - 4)};
  out.push_back({Rayd{o, d}, c, R});
  if (!tilt) return out;
  for (int k : kBelow)
    for (double sgn : {-1.0, 1.0}) {
      out.push_back({Rayd{o, {sgn * tiny_of(d, k), 0, d.z}}, c, R});
      out.push_back({Rayd{o, {0, sgn * tiny_of(d, k), d.z}}, c, R});
    }
  return out;
}

TEST(OracleDD, SphereDiscriminantBelowDoubleDoubleResolution) {
  std::mt19937_64 g(24);
  int decided = 0, fell_back = 0, tangent = 0;
  for (double off : {0.0, 1e3, 1e6, 1e7})
    for (int i = 0; i < 40; ++i) {
      const auto cases = near_tangent_cases(g, off, true);
      for (std::size_t j = 0; j < cases.size(); ++j) {
        SCOPED_TRACE("offset " + std::to_string(off) + " case " + std::to_string(i) + " variant " + std::to_string(j));
        check_sph(cases[j], decided, fell_back);
        if (j == 0) {
          EXPECT_EQ(ref_sphere(cases[j].r, cases[j].c, cases[j].radius).verdict, Verdict::boundary);
          ++tangent;
        }
      }
    }
  EXPECT_GT(tangent, 100);
  EXPECT_GT(decided, 1000);
  EXPECT_GT(fell_back, 1000);
}

// Roots exactly on a midpoint: a Pythagorean quadruple x^2 + y^2 + h^2 = R^2
// puts the ray o = (x, y, h - m), d = (0, 0, 1) through the sphere at t = m and
// m - 2h, m = 2^53 + odd, so t rounds to even (or m = 2^53 + even, a double,
// then with windows ending at the roots); d.x = +-2^-k moves the roots off
// by about 2^-k relative.
TEST(OracleDD, SphereRootsOnAndNextToAMidpointOrADouble) {
  std::mt19937_64 g(25);
  int ties = 0, decided = 0, fell_back = 0;
  for (int i = 0; i < 120; ++i) {
    const auto r24 = [&] { return double((g() >> 40) | (std::uint64_t(1) << 23)); };  // 24 bits
    const double p = r24(), q = r24(), r = r24(), s = r24();
    const double x = p * p + q * q - r * r - s * s, y = 2 * (p * s + q * r), h = std::abs(2 * (q * s - p * r));
    const double R = p * p + q * q + r * r + s * s;  // < 2^50: all of these are exact
    if (h < 0x1p40) continue;
    // m - h < 2^53 so that oz = h - m (odd) is a double.
    // Odd cases: m even, a double, and windows end at the roots or next to them.
    const bool on_double = i % 2 == 1;
    const std::int64_t m = (std::int64_t(1) << 53) + 2 * std::int64_t(g() % std::uint64_t(h / 2)) + (on_double ? 0 : 1);
    const std::int64_t ozi = std::int64_t(h) - m;
    const double oz = double(ozi);
    if (std::int64_t(oz) != ozi) continue;
    // Random axis order, signs and power-of-two scale: all exact.
    const int sc = int(g() % 200) - 100;
    int perm[3] = {0, 1, 2};
    std::shuffle(perm, perm + 3, g);
    const double sx = g() & 1 ? -1 : 1, sy = g() & 1 ? -1 : 1, sd = g() & 1 ? -1 : 1;
    auto place = [&](double vx, double vy, double vz) {
      Vec3d v;
      v[perm[0]] = std::ldexp(sx * vx, sc), v[perm[1]] = std::ldexp(sy * vy, sc), v[perm[2]] = std::ldexp(sd * vz, sc);
      return v;
    };
    const Vec3d o = place(x, y, oz), c = place(0, 0, 0);
    SCOPED_TRACE("case " + std::to_string(i));
    for (int k = -1; k < 12; ++k)
      for (double sgn : {-1.0, 1.0}) {
        if (k < 0 && sgn < 0) continue;
        const double dx = k < 0 ? 0 : sgn * std::ldexp(1.0, -40 - 6 * k);  // 2^-40 .. 2^-106
        const Vec3d d = place(dx, 0, 1);
        const SphCase t{Rayd{o, d}, c, std::ldexp(R, sc)};
        SCOPED_TRACE("d.x " + std::to_string(dx));
        if (k < 0) {
          const auto want = ref_sphere(t.r, t.c, t.radius);
          ASSERT_EQ(want.verdict, Verdict::hit);
          ASSERT_EQ(want.t_far, double(on_double ? m : m % 4 == 1 ? m - 1 : m + 1));  // ties to even
          ties += !on_double;
        }
        check_sph(t, decided, fell_back);
        if (on_double && (k == 6 || k == 8 || k == 10)) {
          const auto want = ref_sphere(t.r, t.c, t.radius);
          for (double x : {want.t, want.t_far})
            check_windows(t, x, [&](const SphCase& w) { check_sph(w, decided, fell_back); });
        }
      }
  }
  EXPECT_GT(ties, 30);
  EXPECT_GT(decided, 300);
  EXPECT_GT(fell_back, 300);
}

// Sphere roots within about 2^-213 of a midpoint between doubles, beyond what
// the exact path's MPFR precision (integer sizes + 96 bits, about 204 here)
// resolves: with x^2 + y^2 + z^2 = (2^53 R)^2 + s for small s (three squares
// found by Cornacchia's method), d = M^-1 (x, y, z) mod 2^53 and
// f = o - c = ((x, y, z) - M d) / 2^53, the polynomial at m = M 2^-53 (M odd,
// 54 bits) is s 2^-106. The first seven were rounded to the wrong side before
// the exact path checked its MPFR guess against the midpoints.
TEST(OracleDD, SphereRootsWithin2ToMinus200OfAMidpoint) {
  // o, d (the centre is 0) and the radius.
  const double rows[][7] = {
      {-4051195949526708, 7782850023437287, 1586050764232668, 2487679796734386, -4188179493722325, -769072061172422,
       697007832366653},
      {5766628429972556, 1027167417059215, 1393763842728614, -3320671313103007, -704778725147500, -872828286441607,
       593272807863166},
      {-5525577283384923, 6056897100884350, 4266243655226884, 3548706529094099, -4273450995290750, -3452550127959786,
       1121031510358420},
      {-3941095255883726, 1649599564797516, -2849806317028729, 3153854704130562, -755640185435070, 2500862218253773,
       1122718083529185},
      {-2920281676067117, 622507534702456, -6499219931495391, 2151335861665850, -884944214738875, 4317732885062178,
       1036226799415471},
      {-3688909925777730, -4271221313648234, -5100990862023190, 2825292349285864, 3638798435719075, 4308719982865379,
       1024000611980459},
      {6333393374454317, 6105515012816005, 5960057286416992, -3224029221767026, -3152106002396731, -3053747686934438,
       929986196951221},
      {-3448660098367940, 855968227025046, 3614291412412241, 2344914797331730, -255861418477873, -2001656729949843,
       709135337676511},
      {-2290723716561240, -1178486710247122, 4319379762138714, 2087273616343293, 1001661033713798, -2820511738386296,
       787123383079334},
      {-5744206471290976, -4781838772127429, 2958981472031143, 3635088414265972, 2197821710752683, -1668660670524170,
       1124082602744863},
      {5372664883307192, 3642900129514919, 7487584694122443, -3183726190753343, -1839023056067541, -4174743016064142,
       674108326895953},
      {5731415092197240, -1292495903330821, 1326867641558878, -3365097265105696, 411532107883973, -552719448956643,
       836267257647740},
  };
  std::vector<SphCase> cases;
  for (const auto& v : rows) cases.push_back({Rayd{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}}, {0, 0, 0}, v[6]});
  int decided = 0, fell_back = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    check_sph(cases[i], decided, fell_back);
    // The same scaled (exactly): positions by 2^-60, d by 2^-70, so t by 2^10.
    SphCase moved = cases[i];
    moved.r.o = moved.r.o * 0x1p-60;
    moved.radius *= 0x1p-60;
    moved.r.d = moved.r.d * 0x1p-70;
    check_sph(moved, decided, fell_back);
  }
  EXPECT_EQ(decided, 0);  // no filter can round these
}

// Every input scaled by 2^s (exact): verdicts and t must not change. Within
// this range of s the double-double filter's range guard starts sending these
// inputs to GMP (products of three or four of them would leave double's
// exponent range, where two_prod's error term is no longer exact and the
// error bounds themselves underflow); on both sides the answers must agree.
TEST(OracleDD, ScaledByPowersOfTwoAcrossTheRangeGuard) {
  std::mt19937_64 g(26);
  std::vector<TriCase> tris;
  std::vector<SphCase> sphs;
  for (int i = 0; i < 6; ++i) {
    for (double off : {0.0, 1e3})
      for (const TriCase& t : edge_and_vertex_cases(g, off, 1.0, true)) tris.push_back(t);
    for (const SphCase& t : near_tangent_cases(g, 100.0, true)) sphs.push_back(t);
  }
  // Short mantissas (a 2^-20 grid) stay exact when scaled deep enough for
  // products of three or four inputs to underflow: rays at edge midpoints and
  // tangent rays, exactly, and nudged by 2^-24.
  std::uniform_real_distribution<double> u(-1, 1);
  auto grid = [&](double sc) { return std::round(u(g) * sc * 0x1p20) * 0x1p-20; };
  for (int i = 0; i < 40; ++i) {
    const Vec3d a{grid(1), grid(1), grid(1)}, b{grid(1), grid(1), grid(1)}, c{grid(1), grid(1), grid(1)};
    const Vec3d P = (a + b) * 0.5, o = P + Vec3d{grid(3), grid(3), grid(3)};
    for (const Vec3d& d : {P - o, P - o + Vec3d{0, 0, 0x1p-24}, P - o - Vec3d{0x1p-24, 0, 0}})
      tris.push_back({Rayd{o, d}, a, b, c});
    const double R = std::ldexp(1.0, int(g() % 8) - 4);
    const Vec3d ctr{grid(4), grid(4), grid(4)};
    const Vec3d so = ctr + Vec3d{R, 0, -4 * R};
    for (const Vec3d& d : {Vec3d{0, 0, 1}, Vec3d{0x1p-24, 0, 1}, Vec3d{-0x1p-24, 0, 1}})
      sphs.push_back({Rayd{so, d}, ctr, R});
  }
  auto exact = [](const Vec3d& v, int s) {
    return std::ldexp(std::ldexp(v.x, s), -s) == v.x && std::ldexp(std::ldexp(v.y, s), -s) == v.y &&
           std::ldexp(std::ldexp(v.z, s), -s) == v.z;
  };
  int checked = 0, decided = 0, fell_back = 0, guard_passed = 0, guard_refused = 0;
  for (int s : {-700, -400, -355, -345, -330, -300, -280, -272, -268, -255,
                -250, -240, -200, 250,  280,  290,  300,  320,  400,  600}) {
    for (std::size_t i = 0; i < tris.size(); ++i) {
      const TriCase& t = tris[i];
      if (!exact(t.r.o, s) || !exact(t.r.d, s) || !exact(t.a, s) || !exact(t.b, s) || !exact(t.c, s)) continue;
      SCOPED_TRACE("2^" + std::to_string(s) + " triangle " + std::to_string(i));
      const TriCase k{Rayd{scale(t.r.o, s), scale(t.r.d, s)}, scale(t.a, s), scale(t.b, s), scale(t.c, s)};
      check_tri(k, decided, fell_back);
      const auto before = ra::oracle::exact_fallbacks();
      const auto got = ra::oracle::triangle(k.r, k.a, k.b, k.c);
      (ra::oracle::exact_fallbacks() == before ? guard_passed : guard_refused) += 1;
      expect_same(got, ra::oracle::triangle(t.r, t.a, t.b, t.c));
      ++checked;
    }
    for (std::size_t i = 0; i < sphs.size(); ++i) {
      const SphCase& t = sphs[i];
      if (!exact(t.r.o, s) || !exact(t.r.d, s) || !exact(t.c, s) || !exact({t.radius, 0, 0}, s)) continue;
      SCOPED_TRACE("2^" + std::to_string(s) + " sphere " + std::to_string(i));
      const SphCase k{Rayd{scale(t.r.o, s), scale(t.r.d, s)}, scale(t.c, s), std::ldexp(t.radius, s)};
      check_sph(k, decided, fell_back);
      const auto before = ra::oracle::exact_fallbacks();
      const auto got = ra::oracle::sphere(k.r, k.c, k.radius);
      (ra::oracle::exact_fallbacks() == before ? guard_passed : guard_refused) += 1;
      expect_same_sphere(got, ra::oracle::sphere(t.r, t.c, t.radius));
      ++checked;
    }
  }
  EXPECT_GT(checked, 3000);
  // The scales straddle the range guard: at 2^s some queries stay within it
  // and are decided by the filters, others fall outside and go to GMP.
  EXPECT_GT(guard_passed, 0);
  EXPECT_GT(guard_refused, 0);
  EXPECT_GT(decided + fell_back, 3000);
}

// t below 2^-1022: the exact path must round it to the subnormal grid once.
// t = oz / 3 with oz = (3 j + 1) 2^-1075, j odd: t = (j + 1/3) 2^-1075 is just
// past the midpoint j 2^-1075, so it rounds up; rounding first to 53 bits
// lands on the midpoint and then ties to even.
TEST(OracleDD, SubnormalTIsRoundedOnce) {
  std::mt19937_64 g(27);
  for (int i = 0; i < 200; ++i) {
    const std::uint64_t j = (std::uint64_t(1) << 52) | (g() & ((std::uint64_t(1) << 50) - 1)) | 1;
    const double oz = std::ldexp(double((3 * j + 1) / 2), -1074);
    const Rayd r{{0.25, 0.25, oz}, {0, 0, -3}};
    SCOPED_TRACE("j " + std::to_string(j));
    const auto got = ra::oracle::triangle(r, A, B, C);
    EXPECT_EQ(got.t, std::ldexp(double((j + 1) / 2), -1074)) << std::hexfloat << got.t;
    expect_same(got, ref_triangle(r, A, B, C));
    // Random subnormal crossings, through other divisors.
    std::uniform_real_distribution<double> u(1, 2);
    const Rayd q{{0.25, 0.25, std::ldexp(u(g), -1030 - int(g() % 40))}, {0, 0, -(1 + double(g() % 1000))}};
    expect_same(ra::oracle::triangle(q, A, B, C), ref_triangle(q, A, B, C));
  }
}

}  // namespace
