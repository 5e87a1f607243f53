// The triangle methods of the registry on cases worked out by hand, each for
// float and double, through both entry points (direct and prepared) and both
// queries (closest hit and any hit).
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "../registry.h"

namespace ra {
namespace {

inline constexpr char kAngles[] = "angles";
inline constexpr char kCramer[] = "cramer";
inline constexpr char kAreas[] = "areas";
inline constexpr char kTriple[] = "triple";
inline constexpr char kSameside[] = "sameside";
inline constexpr char kMoller[] = "moller";
inline constexpr char kWatertight[] = "watertight";
inline constexpr char kBaldwin[] = "baldwin";

template <const char* Name, class T>
struct Case {
  static constexpr const char* name = Name;
  using Scalar = T;
};

template <class P>
class TriangleMethod : public ::testing::Test {
 protected:
  using T = typename P::Scalar;
  using V = Vec3<T>;
  // Tolerance for quantities of order 1 computed in a few operations.
  static constexpr T tol = sizeof(T) == 4 ? T(2e-6) : T(1e-13);

  const TriangleKernels<T>& k() const {
    const Method* m = find_method(P::name);
    if (!m) throw std::runtime_error("method missing from registry");
    return m->template triangle<T>();
  }

  // The closest hit by the direct path; checks that the prepared path and
  // both any-hit entries give the same answer.
  std::optional<TriangleHit<T>> hit(const Ray<T>& r, V a, V b, V c, bool cull) const {
    const auto& kern = k();
    const auto h = kern.hit(r, a, b, c, cull);
    alignas(64) std::array<unsigned char, 512> pre{};
    EXPECT_LE(kern.pre_bytes, pre.size());
    kern.prepare(a, b, c, pre.data());
    const auto hp = kern.hit_pre(r, pre.data(), cull);
    EXPECT_EQ(h.has_value(), hp.has_value()) << "direct and prepared paths disagree";
    if (h && hp) {
      EXPECT_EQ(h->t, hp->t);
      EXPECT_EQ(h->b1, hp->b1);
      EXPECT_EQ(h->b2, hp->b2);
    }
    EXPECT_EQ(kern.any(r, a, b, c, cull), h.has_value()) << "any disagrees with hit";
    EXPECT_EQ(kern.any_pre(r, pre.data(), cull), h.has_value()) << "any_pre disagrees with hit";
    return h;
  }

  static Ray<T> ray(V o, V d, T tmin = T(0), T tmax = std::numeric_limits<T>::infinity()) {
    return Ray<T>{o, d, tmin, tmax};
  }

  // The unit right triangle in z = 0; its front normal (B-A)x(C-A) is +z.
  const V A{0, 0, 0}, B{1, 0, 0}, C{0, 1, 0};
};

using AllTriangleMethods =
    ::testing::Types<Case<kAngles, float>, Case<kAngles, double>, Case<kCramer, float>, Case<kCramer, double>,
                     Case<kAreas, float>, Case<kAreas, double>, Case<kTriple, float>, Case<kTriple, double>,
                     Case<kSameside, float>, Case<kSameside, double>, Case<kMoller, float>, Case<kMoller, double>,
                     Case<kWatertight, float>, Case<kWatertight, double>, Case<kBaldwin, float>,
                     Case<kBaldwin, double>>;

class CaseNames {
 public:
  template <class P>
  static std::string GetName(int) {
    return std::string(P::name) + (sizeof(typename P::Scalar) == 4 ? "_float" : "_double");
  }
};
TYPED_TEST_SUITE(TriangleMethod, AllTriangleMethods, CaseNames);

// A tilted triangle (n = (6, 3, 2), |n| = 7) hit at b = (0.25, 0.5):
// P = 0.25 A + 0.25 B + 0.5 C = (0.25, 0.5, 1.5) = o + 3 d.
TYPED_TEST(TriangleMethod, TiltedTriangleHitAtKnownPointAndBarycentrics) {
  using V = typename TestFixture::V;
  using T = typename TestFixture::T;
  const V a{1, 0, 0}, b{0, 2, 0}, c{0, 0, 3};
  const auto r = this->ray({3.25, 3.5, 4.5}, {-1, -1, -1});
  for (bool cull : {false, true}) {
    const auto h = this->hit(r, a, b, c, cull);
    ASSERT_TRUE(h) << "cull=" << cull;
    EXPECT_NEAR(h->t, T(3), 3 * this->tol);
    EXPECT_NEAR(h->b1, T(0.25), this->tol);
    EXPECT_NEAR(h->b2, T(0.5), this->tol);
    // The barycentrics reproduce the point on the ray.
    const V p = a * (T(1) - h->b1 - h->b2) + b * h->b1 + c * h->b2;
    const V q = r.at(h->t);
    EXPECT_NEAR(p.x, q.x, 4 * this->tol);
    EXPECT_NEAR(p.y, q.y, 4 * this->tol);
    EXPECT_NEAR(p.z, q.z, 4 * this->tol);
  }
}

// An oblique, unnormalised direction: o + 2 d = (0.25, 0.25, 0).
TYPED_TEST(TriangleMethod, ObliqueRayHitsInteriorPoint) {
  using T = typename TestFixture::T;
  const auto r = this->ray({-0.75, -0.25, 4}, {0.5, 0.25, -2});
  const auto h = this->hit(r, this->A, this->B, this->C, false);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(2), 2 * this->tol);
  EXPECT_NEAR(h->b1, T(0.25), this->tol);
  EXPECT_NEAR(h->b2, T(0.25), this->tol);
  EXPECT_NEAR(T(1) - h->b1 - h->b2, T(0.5), 2 * this->tol);
}

TYPED_TEST(TriangleMethod, MissesPointsWellOutside) {
  using T = typename TestFixture::T;
  // (0.6, 0.6): b1 + b2 = 1.2; (-0.1, 0.25): b1 = -0.1; (0.3, -0.2): b2 = -0.2.
  for (auto [x, y] : {std::pair{0.6, 0.6}, {-0.1, 0.25}, {0.3, -0.2}})
    for (bool cull : {false, true})
      EXPECT_FALSE(this->hit(this->ray({T(x), T(y), 1}, {0, 0, -1}), this->A, this->B, this->C, cull))
          << "aim (" << x << ", " << y << ") cull=" << cull;
}

TYPED_TEST(TriangleMethod, MissesTriangleBehindOrigin) {
  // The plane is at t = -1.
  for (bool cull : {false, true})
    EXPECT_FALSE(this->hit(this->ray({0.25, 0.25, -1}, {0, 0, -1}), this->A, this->B, this->C, cull));
}

TYPED_TEST(TriangleMethod, MissesRayParallelToPlane) {
  for (bool cull : {false, true}) {
    // Above the plane, and inside it (through the triangle).
    EXPECT_FALSE(this->hit(this->ray({0.25, 0.25, 1}, {1, 0, 0}), this->A, this->B, this->C, cull));
    EXPECT_FALSE(this->hit(this->ray({-1, 0.25, 0}, {1, 0, 0}), this->A, this->B, this->C, cull));
  }
}

TYPED_TEST(TriangleMethod, HonoursRayWindow) {
  using T = typename TestFixture::T;
  const typename TestFixture::V o{-0.75, -0.25, 4}, d{0.5, 0.25, -2};  // hit at t = 2
  EXPECT_FALSE(this->hit(this->ray(o, d, T(0), T(1.9)), this->A, this->B, this->C, false));
  EXPECT_FALSE(this->hit(this->ray(o, d, T(2.1)), this->A, this->B, this->C, false));
  const auto h = this->hit(this->ray(o, d, T(1.9), T(2.1)), this->A, this->B, this->C, false);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(2), 2 * this->tol);
}

TYPED_TEST(TriangleMethod, CullingRejectsBackFacesOnBothWindings) {
  using T = typename TestFixture::T;
  const auto down = this->ray({0.25, 0.5, 1}, {0, 0, -1});  // meets ABC's front (+z) side
  const auto up = this->ray({0.25, 0.5, -1}, {0, 0, 1});    // meets ABC's back side
  // Winding ABC: front for `down`.
  auto h = this->hit(down, this->A, this->B, this->C, true);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->b1, T(0.25), this->tol);
  EXPECT_NEAR(h->b2, T(0.5), this->tol);
  EXPECT_FALSE(this->hit(up, this->A, this->B, this->C, true));
  EXPECT_TRUE(this->hit(up, this->A, this->B, this->C, false));
  // Winding ACB: the front is -z; the barycentrics swap with the vertices.
  EXPECT_FALSE(this->hit(down, this->A, this->C, this->B, true));
  h = this->hit(down, this->A, this->C, this->B, false);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(1), this->tol);
  EXPECT_NEAR(h->b1, T(0.5), this->tol);
  EXPECT_NEAR(h->b2, T(0.25), this->tol);
  h = this->hit(up, this->A, this->C, this->B, true);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->t, T(1), this->tol);
}

}  // namespace
}  // namespace ra
