// The sphere methods on cases worked out by hand (centre (1, 2, 3), radius 2),
// float and double; codeproject's far-root bug shown for what it is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "../registry.h"

namespace ra {
namespace {

inline constexpr char kKraus[] = "kraus";
inline constexpr char kCodeprojectFixed[] = "codeproject-fixed";
inline constexpr char kStable[] = "stable";

template <const char* Name, class T>
struct Case {
  static constexpr const char* name = Name;
  using Scalar = T;
};

template <class P>
class SphereMethod : public ::testing::Test {
 protected:
  using T = typename P::Scalar;
  using V = Vec3<T>;
  static constexpr T tol = sizeof(T) == 4 ? T(1e-5) : T(1e-12);
  const V c{1, 2, 3};
  const T radius = 2;
  std::optional<SurfaceHit<T>> hit(V o_rel, V d, T tmin = 0, T tmax = std::numeric_limits<T>::infinity()) const {
    const auto& k = find_method(P::name)->template sphere<T>();
    const Ray<T> r{c + o_rel, d, tmin, tmax};
    const auto h = k.hit(r, c, radius);
    EXPECT_EQ(k.any(r, c, radius), h.has_value());
    return h;
  }
};

using CorrectSphereMethods =
    ::testing::Types<Case<kKraus, float>, Case<kKraus, double>, Case<kCodeprojectFixed, float>,
                     Case<kCodeprojectFixed, double>, Case<kStable, float>, Case<kStable, double>>;
class CaseNames {
 public:
  template <class P>
  static std::string GetName(int) {
    std::string n = P::name;
    for (char& ch : n)
      if (ch == '-') ch = '_';
    return n + (sizeof(typename P::Scalar) == 4 ? "_float" : "_double");
  }
};
TYPED_TEST_SUITE(SphereMethod, CorrectSphereMethods, CaseNames);

// From 5 above the centre, straight down: roots 3 (entry) and 7 (exit).
TYPED_TEST(SphereMethod, HitsNearSideFromOutside) {
  using T = typename TestFixture::T;
  const auto h = this->hit({0, 0, 5}, {0, 0, -1});
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(3), 3 * this->tol);
}

// |d| = 2 halves t; |d| = 5 along (-3, 0, -4) from distance 5: roots 3/5, 7/5.
TYPED_TEST(SphereMethod, NonUnitDirectionKeepsCallersParametrisation) {
  using T = typename TestFixture::T;
  auto h = this->hit({0, 0, 5}, {0, 0, -2});
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(1.5), 2 * this->tol);
  h = this->hit({3, 0, 4}, {-3, 0, -4});
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(0.6), this->tol);
}

TYPED_TEST(SphereMethod, Misses) {
  EXPECT_FALSE(this->hit({3, 0, 5}, {0, 0, -1}));  // passes at distance 3 > 2
  EXPECT_FALSE(this->hit({0, 0, 5}, {0, 0, 1}));   // sphere behind: roots -7, -3
  EXPECT_FALSE(this->hit({0, 0, 5}, {1, 0, 0}));   // parallel to the tangent plane, above
}

// From inside (1 above the centre, going down): roots -1 and 3; the exit.
TYPED_TEST(SphereMethod, FromInsideHitsExit) {
  using T = typename TestFixture::T;
  const auto h = this->hit({0, 0, 1}, {0, 0, -1});
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(3), 3 * this->tol);
}

TYPED_TEST(SphereMethod, HonoursRayWindow) {
  using T = typename TestFixture::T;
  EXPECT_FALSE(this->hit({0, 0, 5}, {0, 0, -1}, T(0), T(2.9)));
  const auto h = this->hit({0, 0, 5}, {0, 0, -1}, T(3.1));  // skips the entry: the exit
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(7), 7 * this->tol);
  EXPECT_FALSE(this->hit({0, 0, 5}, {0, 0, -1}, T(7.1)));
}

// A ray starting on the surface (roots 0 and 4): kraus drops t <= epsilon5
// and reports the far side; the others honour the window, which admits t = 0.
TYPED_TEST(SphereMethod, OriginOnSurface) {
  using T = typename TestFixture::T;
  const auto h = this->hit({0, 0, 2}, {0, 0, -1});
  ASSERT_TRUE(h);
  if (std::string(TypeParam::name) == "kraus")
    EXPECT_NEAR(h->t, T(4), 4 * this->tol);
  else
    EXPECT_NEAR(h->t, T(0), 4 * this->tol);
}

template <class T>
std::optional<SurfaceHit<T>> sphere_hit(const char* name, const Ray<T>& r, Vec3<T> c, T rad) {
  return find_method(name)->template sphere<T>().hit(r, c, rad);
}

// How codeproject is wrong: from outside it returns the exit (t = 7, not 3);
// from inside it happens to be right; behind, both roots are negative: miss.
TEST(SphereCodeproject, ReturnsFarRoot) {
  const Vec3d c{1, 2, 3};
  auto h = sphere_hit<double>("codeproject", Rayd{c + Vec3d{0, 0, 5}, {0, 0, -1}}, c, 2.0);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->t, 7.0);
  h = sphere_hit<double>("codeproject", Rayd{c + Vec3d{0, 0, 1}, {0, 0, -1}}, c, 2.0);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->t, 3.0);
  EXPECT_FALSE(sphere_hit<double>("codeproject", Rayd{c + Vec3d{0, 0, 5}, {0, 0, 1}}, c, 2.0));
  EXPECT_TRUE(find_method("codeproject")->wrong_on_purpose);
}

// On random rays from outside: codeproject's t is a point on the sphere where
// the ray leaves it (d.(P - c) > 0), and equals codeproject-fixed's far root.
TEST(SphereCodeproject, RandomRaysGetExitPointEqualToFixedFarRoot) {
  constexpr std::uint64_t seed = 99;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int i = 0; i < 10000; ++i) {
    const Vec3d c{u(rng), u(rng), u(rng)};
    const double rad = 0.5 + std::abs(u(rng));
    const Vec3d o = c + Vec3d{u(rng), u(rng), u(rng)} * 8.0;
    const Vec3d d = (c + Vec3d{u(rng), u(rng), u(rng)} * rad) - o;
    if (length(o - c) < rad * 1.01) continue;
    const auto near = sphere_hit<double>("codeproject-fixed", Rayd{o, d}, c, rad);
    if (!near) continue;
    const auto far = sphere_hit<double>("codeproject-fixed", Rayd{o, d, near->t * (1 + 1e-9)}, c, rad);
    const auto wrong = sphere_hit<double>("codeproject", Rayd{o, d}, c, rad);
    ASSERT_TRUE(far && wrong) << "ray " << i << " seed " << seed;
    EXPECT_EQ(wrong->t, far->t) << "ray " << i << " seed " << seed;
    EXPECT_GT(wrong->t, near->t) << "ray " << i << " seed " << seed;
    const Vec3d p = o + d * wrong->t;
    EXPECT_NEAR(length(p - c), rad, 1e-9) << "ray " << i << " seed " << seed;
    EXPECT_GT(dot(p - c, d), 0.0) << "leaving the sphere; ray " << i << " seed " << seed;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// kraus, codeproject-fixed and stable agree on random rays (double), from
// outside and inside, with unnormalised directions.
TEST(SphereAgreement, CorrectMethodsAgreeOnRandomRays) {
  constexpr std::uint64_t seed = 1234;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3d c{u(rng), u(rng), u(rng)};
    const double rad = 0.5 + std::abs(u(rng));
    const Vec3d o = c + Vec3d{u(rng), u(rng), u(rng)} * 4.0;
    // Half aimed near the sphere, half anywhere; lengths 0.1 .. 3.1.
    const Vec3d aim = i % 2 ? c + Vec3d{u(rng), u(rng), u(rng)} * rad : o + Vec3d{u(rng), u(rng), u(rng)};
    const Vec3d d = normalize(aim - o) * (0.1 + 3 * std::abs(u(rng)));
    const Rayd r{o, d};
    const auto s = sphere_hit<double>("stable", r, c, rad);
    // Skip near-tangent rays and origins within epsilon5 of the surface.
    const Vec3d f = o - c;
    const double disc = rad * rad - dot(f, f) + dot(f, d) * dot(f, d) / dot(d, d);
    if (std::abs(disc) < 1e-6 || std::abs(length(f) - rad) < 1e-3) continue;
    for (const char* m : {"kraus", "codeproject-fixed"}) {
      const auto h = sphere_hit<double>(m, r, c, rad);
      ASSERT_EQ(h.has_value(), s.has_value()) << m << " ray " << i << " seed " << seed;
      if (h) {
        EXPECT_NEAR(h->t, s->t, 1e-9 * (1 + s->t)) << m << " ray " << i << " seed " << seed;
      }
    }
    hits += s.has_value();
  }
  EXPECT_GT(hits, 4000);
}

TEST(Plane, HitsBothSidesAndHonoursWindow) {
  const auto& k = find_method("plane")->plane<double>();
  const Vec3d n{0, 0, 1};
  auto h = k.hit(Rayd{{1, 1, 5}, {0, 0, -1}}, n, 2.0);  // plane z = 2
  ASSERT_TRUE(h);
  EXPECT_EQ(h->t, 3.0);
  h = k.hit(Rayd{{1, 1, -1}, {0, 0, 2}}, n, 2.0);  // from below, |d| = 2
  ASSERT_TRUE(h);
  EXPECT_EQ(h->t, 1.5);
  EXPECT_FALSE(k.hit(Rayd{{1, 1, 5}, {1, 0, 0}}, n, 2.0));           // parallel
  EXPECT_FALSE(k.hit(Rayd{{1, 1, 5}, {0, 0, 1}}, n, 2.0));           // behind
  EXPECT_FALSE(k.hit(Rayd{{1, 1, 5}, {0, 0, -1}, 0, 2.5}, n, 2.0));  // beyond tmax
  EXPECT_FALSE(k.any(Rayd{{1, 1, 5}, {0, 0, -1}, 3.5}, n, 2.0));     // before tmin
}

}  // namespace
}  // namespace ra
