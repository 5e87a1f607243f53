// The exact method (exact.h): verdicts and t whose right answers come from
// geometry built to be exact (grid points, powers of two, IEEE division's
// own correct rounding), adversarial inputs (subnormal, near overflow,
// shared edges and vertices, grazing, the window's ends), and the filter
// against the GMP path on the same cases.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "methods/exact.h"

namespace ra {
namespace {

template <class T>
class ExactTyped : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ExactTyped, Precisions);

template <class T>
std::optional<TriangleHit<T>> hit(const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                  bool cull = false) {
  return exact::hit(r, a, b, c, cull);
}

// The unit right triangle in the plane z = 1, and rays from the origin.
template <class T>
struct Unit {
  Vec3<T> a{0, 0, 1}, b{1, 0, 1}, c{0, 1, 1};
};

TYPED_TEST(ExactTyped, EdgesAndVerticesBelongToTheTriangle) {
  using T = TypeParam;
  const Unit<T> u;
  // Vertices, edge midpoints and an interior point: all hits at t = 1.
  for (const Vec3<T> p : {u.a, u.b, u.c, Vec3<T>{T(0.5), 0, 1}, Vec3<T>{0, T(0.5), 1}, Vec3<T>{T(0.5), T(0.5), 1},
                          Vec3<T>{T(0.25), T(0.25), 1}}) {
    const auto h = hit(Ray<T>{{0, 0, 0}, p}, u.a, u.b, u.c);
    ASSERT_TRUE(h.has_value()) << p;
    EXPECT_EQ(h->t, T(1)) << p;
  }
  // One ulp outside each edge: misses.
  const T out = -std::numeric_limits<T>::denorm_min();
  const T above = std::nextafter(T(0.5), T(1));
  for (const Vec3<T> p : {Vec3<T>{T(0.5), out, 1}, Vec3<T>{out, T(0.5), 1}, Vec3<T>{above, T(0.5), 1}})
    EXPECT_FALSE(hit(Ray<T>{{0, 0, 0}, p}, u.a, u.b, u.c).has_value()) << p;
}

// A ray through the shared edge of two coplanar triangles on either side of
// it, from random origins: the point aimed at is inside the pair's union
// (the edge's interior), so a ray through it, or through the rounding of
// d = target - o beside it, hits at least one of them (no leak), and two
// hits are one crossing (the same plane: the same exact t, the same bits).
TYPED_TEST(ExactTyped, SharedEdgesNeverLeak) {
  using T = TypeParam;
  std::mt19937 g(29);
  std::uniform_real_distribution<T> u(-3, 3), s(T(0.1), T(0.9));
  const Vec3<T> p0{T(0.3), T(-0.7), 0}, p1{T(1.1), T(0.4), 0};
  const Vec3<T> l{T(-0.5), T(0.9), 0}, r{T(0.9), T(-1.2), 0};  // either side of p0-p1
  for (int i = 0; i < 5000; ++i) {
    const Vec3<T> o{u(g), u(g), u(g)};
    const Vec3<T> target = p0 + (p1 - p0) * s(g);
    const Ray<T> ray{o, target - o};
    const auto h1 = hit(ray, p0, p1, l), h2 = hit(ray, p1, p0, r);
    EXPECT_TRUE(h1.has_value() || h2.has_value()) << "ray " << i;
    if (h1 && h2) {
      EXPECT_EQ(h1->t, h2->t) << "ray " << i;
    }
  }
}

// A fan of 6 triangles around a grid vertex, rays aimed exactly at it
// (d = V - o exact on the grid): every triangle holds V, so all 6 hit, at
// one t.
TYPED_TEST(ExactTyped, SharedVertexHitsTheWholeFan) {
  using T = TypeParam;
  std::mt19937 g(31);
  std::uniform_int_distribution<int> grid(-64, 64);
  const Vec3<T> v{T(0.5), T(0.25), T(0.125)};
  Vec3<T> ring[6];
  for (int k = 0; k < 6; ++k) ring[k] = v + Vec3<T>{T(std::cos(k * 1.047)), T(std::sin(k * 1.047)), T(0.1) * T(k % 2)};
  for (int i = 0; i < 2000; ++i) {
    const Vec3<T> o{T(grid(g)) / 16, T(grid(g)) / 16, T(grid(g)) / 16 + 5};
    const Ray<T> ray{o, v - o};  // exact: small dyadic numbers
    int hits = 0;
    T t0 = -1;
    for (int k = 0; k < 6; ++k)
      if (const auto h = hit(ray, v, ring[k], ring[(k + 1) % 6])) {
        ++hits;
        if (t0 < 0) t0 = h->t;
        EXPECT_EQ(h->t, t0);
        EXPECT_EQ(h->t, T(1));
      }
    EXPECT_EQ(hits, 6) << "ray " << i;
  }
}

// t = k / m for the plane z = k and d_z = m: IEEE division is correctly
// rounded, so T(k) / T(m) is the correctly rounded t. The method promises
// t within 1 ulp (faithful), and correct rounding where its enclosure
// allows: float's (computed in double) nearly always.
TYPED_TEST(ExactTyped, TIsFaithfullyRounded) {
  using T = TypeParam;
  std::mt19937 g(7);
  std::uniform_int_distribution<int> ki(1, 1000), mi(1, 999);
  int correct = 0;
  const int n = 5000;
  for (int i = 0; i < n; ++i) {
    const T k = T(ki(g)), m = T(mi(g));
    const Vec3<T> a{-5000, -5000, k}, b{5000, -5000, k}, c{0, 5000, k};
    const T dx = T(mi(g)) / T(1024), dy = T(mi(g)) / T(-2048);
    const auto h = hit(Ray<T>{{0, 0, 0}, {dx, dy, m}}, a, b, c);
    ASSERT_TRUE(h.has_value());
    const T want = k / m;
    EXPECT_TRUE(h->t == want || h->t == std::nextafter(want, T(0)) || h->t == std::nextafter(want, T(2000)))
        << k << " / " << m << ": " << h->t;
    correct += h->t == want;
  }
  EXPECT_GE(correct, sizeof(T) == 4 ? n * 99 / 100 : n * 8 / 10);
}

// The window is closed at both ends, and t below 0 never counts.
TYPED_TEST(ExactTyped, WindowIsClosed) {
  using T = TypeParam;
  const Unit<T> u;
  Ray<T> r{{0, 0, 0}, {T(0.25), T(0.25), 1}};
  r.tmax = 1;
  EXPECT_TRUE(hit(r, u.a, u.b, u.c).has_value());
  r.tmax = std::nextafter(T(1), T(0));
  EXPECT_FALSE(hit(r, u.a, u.b, u.c).has_value());
  r.tmax = std::numeric_limits<T>::infinity();
  r.tmin = 1;
  EXPECT_TRUE(hit(r, u.a, u.b, u.c).has_value());
  r.tmin = std::nextafter(T(1), T(2));
  EXPECT_FALSE(hit(r, u.a, u.b, u.c).has_value());
  // Behind the origin: never, whatever tmin says.
  Ray<T> back{{0, 0, 2}, {T(0.25), T(0.25), 1}};
  back.tmin = -10;
  EXPECT_FALSE(hit(back, u.a, u.b, u.c).has_value());
  // At the origin (t = 0): a hit when the window starts at 0.
  Ray<T> on{{T(0.25), T(0.25), 1}, {0, 0, 1}};
  const auto h0 = hit(on, u.a, u.b, u.c);
  ASSERT_TRUE(h0.has_value());
  EXPECT_EQ(h0->t, T(0));
}

// Scaling every position and d by 2^k changes nothing exact: the verdict
// and t are the same. Pushed to subnormal and near-overflow magnitudes,
// where any unguarded floating-point evaluation under- or overflows.
TYPED_TEST(ExactTyped, SubnormalAndNearOverflowScalesDecideAsUnscaled) {
  using T = TypeParam;
  constexpr bool kFloat = sizeof(T) == 4;
  // float: 2^-120 .. 2^-140 reach subnormals (below 2^-126); 2^120 nears 2^128.
  const int ks[] = {kFloat ? -120 : -1000, kFloat ? -135 : -1040, kFloat ? 100 : 900, kFloat ? 120 : 1010};
  std::mt19937 g(11);
  std::uniform_int_distribution<int> grid(-8, 8);
  int compared = 0, hits = 0;
  for (int i = 0; i < 3000; ++i) {
    // Small integers: exact at every scale down to 2^-149+3 (float) / 2^-1074+3.
    auto p = [&] { return Vec3<T>{T(grid(g)), T(grid(g)), T(grid(g))}; };
    const Vec3<T> a = p(), b = p(), c = p(), o = p(), d = p();
    const auto h = hit(Ray<T>{o, d}, a, b, c);
    hits += h.has_value();
    for (int k : ks) {
      const T s = std::ldexp(T(1), k);
      const auto hs = hit(Ray<T>{o * s, d * s}, a * s, b * s, c * s);
      ASSERT_EQ(h.has_value(), hs.has_value()) << "case " << i << " at 2^" << k;
      if (h) {
        EXPECT_EQ(h->t, hs->t) << "case " << i << " at 2^" << k;
      }
      ++compared;
    }
  }
  EXPECT_GT(hits, 100);  // not vacuous
  EXPECT_EQ(compared, 3000 * 4);
}

// Huge coordinates with a small triangle far out (double: 1e300, float:
// 1e30): the differences are what decides; they are decided exactly.
TYPED_TEST(ExactTyped, FarOutSmallTriangle) {
  using T = TypeParam;
  const T far = sizeof(T) == 4 ? T(0x1p100) : T(0x1p1000);
  const T step = far * std::numeric_limits<T>::epsilon();  // one ulp of far
  const Vec3<T> a{far, far, far}, b{far + 4 * step, far, far}, c{far, far + 4 * step, far};
  const Vec3<T> o{far + step, far + step, 0};
  const auto h = hit(Ray<T>{o, {0, 0, 1}}, a, b, c);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->t, far);
  // On the hypotenuse (x + y = 4 steps): still a hit; one step beyond: a miss.
  EXPECT_TRUE(hit(Ray<T>{{far + 2 * step, far + 2 * step, 0}, {0, 0, 1}}, a, b, c).has_value());
  EXPECT_FALSE(hit(Ray<T>{{far + 3 * step, far + 2 * step, 0}, {0, 0, 1}}, a, b, c).has_value());
}

// Grazing rays: almost in the plane, they still hit where exact geometry
// says, at the right t; a ray in the plane (coplanar) misses.
TYPED_TEST(ExactTyped, GrazingRays) {
  using T = TypeParam;
  const Unit<T> u;
  for (int k = 4; k < (sizeof(T) == 4 ? 60 : 400); k += 3) {
    const T tilt = std::ldexp(T(1), -k);
    // From (-1, 0.25, 1 - tilt) along (1, 0, tilt): meets z = 1 at x = 0, t = 1.
    const Ray<T> r{{-1, T(0.25), 1 - tilt}, {1, 0, tilt}};
    if (1 - tilt == T(1)) break;  // the origin rounded into the plane
    const auto h = hit(r, u.a, u.b, u.c);
    ASSERT_TRUE(h.has_value()) << "tilt 2^-" << k;
    EXPECT_EQ(h->t, T(1)) << "tilt 2^-" << k;
  }
  EXPECT_FALSE(hit(Ray<T>{{-1, T(0.25), 1}, {1, 0, 0}}, u.a, u.b, u.c).has_value());
}

TYPED_TEST(ExactTyped, CullKeepsOnlyFrontFaces) {
  using T = TypeParam;
  const Unit<T> u;  // normal (B - A) x (C - A) = +z
  const Ray<T> down{{T(0.25), T(0.25), 2}, {0, 0, -1}}, up{{T(0.25), T(0.25), 0}, {0, 0, 1}};
  EXPECT_TRUE(hit(down, u.a, u.b, u.c, true).has_value());
  EXPECT_FALSE(hit(up, u.a, u.b, u.c, true).has_value());
  EXPECT_TRUE(hit(up, u.a, u.b, u.c, false).has_value());
}

TYPED_TEST(ExactTyped, NonFiniteInputsAndDegenerateTrianglesMiss) {
  using T = TypeParam;
  const Unit<T> u;
  const T inf = std::numeric_limits<T>::infinity(), nan = std::numeric_limits<T>::quiet_NaN();
  const Ray<T> r{{0, 0, 0}, {T(0.25), T(0.25), 1}};
  EXPECT_FALSE(hit(Ray<T>{{0, 0, 0}, {nan, T(0.25), 1}}, u.a, u.b, u.c).has_value());
  EXPECT_FALSE(hit(Ray<T>{{0, inf, 0}, {T(0.25), T(0.25), 1}}, u.a, u.b, u.c).has_value());
  EXPECT_FALSE(hit(r, Vec3<T>{nan, 0, 1}, u.b, u.c).has_value());
  EXPECT_FALSE(hit(r, u.a, Vec3<T>{inf, 0, 1}, u.c).has_value());
  Ray<T> nw = r;
  nw.tmax = nan;
  EXPECT_FALSE(hit(nw, u.a, u.b, u.c).has_value());
  EXPECT_FALSE(hit(r, u.a, u.a, u.c).has_value());                             // two equal vertices
  EXPECT_FALSE(hit(r, u.a, Vec3<T>{T(0.5), 0, 1}, u.b).has_value());           // collinear
  EXPECT_FALSE(hit(Ray<T>{{0, 0, 0}, {0, 0, 0}}, u.a, u.b, u.c).has_value());  // d = 0
}

// The filter (with its stage 2) and the GMP path are two evaluations of
// the same exact answer: on random cases, many near edges, both agree on
// every verdict and on t bit for bit.
TYPED_TEST(ExactTyped, FilterAgreesWithTheExactPath) {
  using T = TypeParam;
  std::mt19937 g(3);
  std::uniform_real_distribution<T> u(-1, 1);
  std::uniform_int_distribution<int> pick(0, 3);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3<T> a{u(g), u(g), u(g)}, b{u(g), u(g), u(g)}, c{u(g), u(g), u(g)};
    const Vec3<T> o = Vec3<T>{u(g), u(g), u(g)} * T(4);
    // Aim at an edge point (many boundary and near-boundary cases) or anywhere.
    const T s = (u(g) + 1) / 2;
    const Vec3<T> target = pick(g) == 0 ? a + (b - a) * s : pick(g) == 1 ? b + (c - b) * s : a + (c - a) * s * T(1.5);
    Ray<T> r{o, target - o};
    if (pick(g) == 0) r.tmax = T(0.5) + (u(g) + 1);
    const bool cull = pick(g) == 0;
    const auto f = exact::hit(r, a, b, c, cull);
    const auto e = exact::hit_exact(r, a, b, c, cull);
    ASSERT_EQ(f.has_value(), e.has_value()) << "case " << i;
    // The prepared form answers bit for bit as the direct one.
    const auto p = exact::hit(r, exact::detail::prepare(a, b, c), cull);
    ASSERT_EQ(p.has_value(), f.has_value()) << "case " << i;
    if (p) {
      EXPECT_TRUE(p->t == f->t && p->b1 == f->b1 && p->b2 == f->b2) << "case " << i;
    }
    EXPECT_EQ(exact::any(r, a, b, c, cull), e.has_value()) << "case " << i;
    if (f) {
      ++hits;
      EXPECT_EQ(f->t, e->t) << "case " << i;
      // The filter's barycentrics: within its stated bound; here (well
      // conditioned cases) far inside 1e-4 (float) / 1e-12 (double).
      const T tol = sizeof(T) == 4 ? T(1e-4) : T(1e-12);
      EXPECT_NEAR(f->b1, e->b1, tol) << "case " << i;
      EXPECT_NEAR(f->b2, e->b2, tol) << "case " << i;
    }
  }
  EXPECT_GT(hits, 2000);
}

// A ray of ordinary scale against an ordinary triangle, but with a tiny
// or subnormal direction component or offset from the origin to the first
// vertex: the filter's bounds take products of those with the triangle's
// terms, which underflow; they must still bound the error (the filter
// answers as the exact path, verdict and t, on every case).
TYPED_TEST(ExactTyped, TinyRayComponentsWithAnOrdinaryTriangle) {
  using T = TypeParam;
  constexpr bool kFloat = sizeof(T) == 4;
  const int lo = kFloat ? -149 : -1074, hi = kFloat ? -100 : -990;
  std::mt19937 g(17);
  std::uniform_real_distribution<T> u(-1, 1);
  std::uniform_int_distribution<int> expo(lo, hi), axis(0, 2), pick(0, 2);
  int hits = 0, tiny_t = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3<T> a{u(g), u(g), u(g)};
    const Vec3<T> b{u(g), u(g), u(g)}, c{u(g), u(g), u(g)};
    Vec3<T> o = Vec3<T>{u(g), u(g), u(g)} * T(3);
    Vec3<T> d = (a + b + c) * T(1.0 / 3) - o;
    const int k = axis(g);
    const T tiny = std::ldexp(T(u(g) < 0 ? -1 : 1), expo(g));
    switch (pick(g)) {
      case 0:  // one direction component tiny
        d[k] = tiny;
        break;
      case 1:  // the origin a tiny step from the first vertex (its
               // coordinate 0 there), the ray across the plane towards the
               // inside: t is tiny, or the ray starts behind the plane
        a[k] = 0;
        o = a;
        o[k] = tiny;
        d = cross(b - a, c - a) + ((b + c) * T(0.5) - a) * T(0.25);
        break;
      default:  // both
        a[k] = 0;
        o = a;
        o[k] = tiny;
        d = cross(b - a, c - a) + ((b + c) * T(0.5) - a) * T(0.25);
        d[(k + 1) % 3] = tiny;
        break;
    }
    const Ray<T> r{o, d};
    const auto f = exact::hit(r, a, b, c, false);
    const auto e = exact::hit_exact(r, a, b, c, false);
    ASSERT_EQ(f.has_value(), e.has_value()) << "case " << i;
    const auto p = exact::hit(r, exact::detail::prepare(a, b, c), false);
    ASSERT_EQ(p.has_value(), f.has_value()) << "case " << i;
    if (f) {
      ++hits;
      tiny_t += f->t < T(1e-20);
      // Faithful: e's t is correctly rounded, f's one of the two T values
      // around the exact t, so at most one ulp from e's.
      EXPECT_TRUE(f->t == e->t || f->t == std::nextafter(e->t, T(INFINITY)) ||
                  f->t == std::nextafter(e->t, -T(INFINITY)))
          << "case " << i << ": " << f->t << " vs " << e->t;
      EXPECT_EQ(p->t, f->t) << "case " << i;
    }
  }
  EXPECT_GT(hits, 1000);   // not vacuous
  EXPECT_GT(tiny_t, 100);  // rays leaving a vertex: t tiny
}

// Culling from the prepared normal (before stage 1) rejects only certain
// back faces: rays all but in the triangle's plane, det of either sign down
// to a few ulps, culled or not, answer as the direct form and the exact
// path.
TYPED_TEST(ExactTyped, PreparedCullingOnNearlyCoplanarRays) {
  using T = TypeParam;
  std::mt19937 g(23);
  std::uniform_real_distribution<T> u(-1, 1);
  std::uniform_int_distribution<int> ulps(-40, 40);
  int front = 0, back = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3<T> a{u(g), u(g), u(g)}, b{u(g), u(g), u(g)}, c{u(g), u(g), u(g)};
    const Vec3<T> target = a + (b - a) * T(0.25) + (c - a) * T(0.25);
    // Along the plane, then tilted by a few ulps of the normal's direction.
    const Vec3<T> n = cross(b - a, c - a);
    const Vec3<T> along = (b - a) * u(g) + (c - a) * u(g);
    const Vec3<T> d = along + n * (T(ulps(g)) * std::numeric_limits<T>::epsilon());
    const Ray<T> r{target - d, d};
    const auto pre = exact::detail::prepare(a, b, c);
    const auto e = exact::hit_exact(r, a, b, c, true);
    const auto f = exact::hit(r, pre, true);
    ASSERT_EQ(f.has_value(), e.has_value()) << "case " << i;
    ASSERT_EQ(exact::hit(r, a, b, c, true).has_value(), e.has_value()) << "case " << i;
    ASSERT_EQ(exact::any(r, pre, true), e.has_value()) << "case " << i;
    const auto all = exact::hit_exact(r, a, b, c, false);
    front += e.has_value();
    back += all.has_value() && !e.has_value();
  }
  EXPECT_GT(front, 1000);  // both sides met, near det = 0
  EXPECT_GT(back, 1000);
}

// Most of a random batch is decided without the exact path.
TYPED_TEST(ExactTyped, FilterDecidesRandomCases) {
  using T = TypeParam;
  std::mt19937 g(5);
  std::uniform_real_distribution<T> u(-1, 1);
  const exact::Fallbacks before = exact::fallbacks();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vec3<T> a{u(g), u(g), u(g)}, b{u(g), u(g), u(g)}, c{u(g), u(g), u(g)};
    const Vec3<T> o = Vec3<T>{u(g), u(g), u(g)} * T(3);
    exact::hit(Ray<T>{o, (a + b + c) * T(0.25) - o}, a, b, c, false);
  }
  const exact::Fallbacks after = exact::fallbacks();
  EXPECT_LT(after.exact - before.exact, std::uint64_t(n / 100));
}

}  // namespace
}  // namespace ra
