// What the document methods do differently from the references, by design of
// their documents: tolerances that accept points outside, strict or inclusive
// edges, a near-hit cut-off, a scale-dependent parallel test, a printed sign.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "methods/angles.h"
#include "methods/areas.h"
#include "methods/cramer.h"
#include "methods/sameside.h"
#include "../registry.h"

namespace ra {
namespace {

template <class T>
bool hits(const char* name, const Ray<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) {
  return find_method(name)->template triangle<T>().hit(r, a, b, c, false).has_value();
}

template <class T>
class DocumentMethod : public ::testing::Test {
 protected:
  using V = Vec3<T>;
  // The unit right triangle in z = 0 (area 1/2, unit normal +z).
  const V A{0, 0, 0}, B{1, 0, 0}, C{0, 1, 0};
  // A vertical ray down through (x, y, 0), starting at height h.
  static Ray<T> down(T x, T y, T h = T(1)) { return Ray<T>{V{x, y, h}, V{0, 0, -1}}; }
};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(DocumentMethod, Precisions);

// (fa x fb).n = 2 area(PAB) = -y for P = (x, y) below edge AB here, so
// MINUS_ZERO = -1e-4 accepts points up to 1e-4 outside this unit triangle.
TYPED_TEST(DocumentMethod, AnglesMinusZeroAcceptsPointsSlightlyOutside) {
  using T = TypeParam;
  EXPECT_TRUE(hits<T>("angles", this->down(T(0.5), T(-5e-5)), this->A, this->B, this->C));
  EXPECT_FALSE(hits<T>("moller", this->down(T(0.5), T(-5e-5)), this->A, this->B, this->C));
  EXPECT_FALSE(hits<T>("angles", this->down(T(0.5), T(-2e-4)), this->A, this->B, this->C));
}

// The tolerance is an area, not a distance: on a triangle 10x larger the same
// 5e-5 offset gives 2 area(PAB) = 10 * 5e-5 = 5e-4 and is rejected.
TYPED_TEST(DocumentMethod, AnglesToleranceScalesWithEdgeLength) {
  using T = TypeParam;
  using V = Vec3<T>;
  EXPECT_FALSE(hits<T>("angles", this->down(T(5), T(-5e-5)), V{0, 0, 0}, V{10, 0, 0}, V{0, 10, 0}));
}

// PLUS_ZERO as the plane step's parallel threshold: |cos| = 1e-6 < 1e-5.
TYPED_TEST(DocumentMethod, AnglesTreatsNearlyParallelRayAsParallel) {
  using T = TypeParam;
  const Ray<T> r{{T(-0.75), T(0.25), T(1e-6)}, {T(1), T(0), T(-1e-6)}};  // meets (0.25, 0.25, 0)
  EXPECT_FALSE(hits<T>("angles", r, this->A, this->B, this->C));
  EXPECT_TRUE(hits<T>("moller", r, this->A, this->B, this->C));
}

// Points exactly on an edge: cramer's strict bounds reject them; the
// inclusive methods accept them. All arithmetic here is exact.
TYPED_TEST(DocumentMethod, CramerRejectsEdgePointsInclusiveMethodsAccept) {
  using T = TypeParam;
  const auto r = this->down(T(0.5), T(0));  // on AB
  EXPECT_FALSE(hits<T>("cramer", r, this->A, this->B, this->C));
  for (const char* m : {"triple", "sameside", "moller", "watertight", "baldwin", "angles", "areas"})
    EXPECT_TRUE(hits<T>(m, r, this->A, this->B, this->C)) << m;
  EXPECT_FALSE(hits<T>("cramer", this->down(T(0), T(0)), this->A, this->B, this->C));  // vertex A
  EXPECT_TRUE(hits<T>("triple", this->down(T(0), T(0)), this->A, this->B, this->C));
}

// Regression for a misprint in seeds/000 §2.2: its t = (f(ak-jb) + e(jc-al) +
// d(bl-kc)) / M, evaluated by hand for the ray down through (0.25, 0.25) from
// height 1: a=-1 b=0 c=0 d=0 e=-1 f=0 g=0 h=0 i=-1 j=-0.25 k=-0.25 l=-1, so
// the numerator is e(jc - al) = -1 * (0 - 1) = 1 and M = a(ei - hf) = -1:
// t = -1, behind the origin. cramer.h uses the minus sign and finds t = +1.
TYPED_TEST(DocumentMethod, CramerUsesCorrectedSignOfPrintedT) {
  using T = TypeParam;
  const auto h = cramer::hit(this->down(T(0.25), T(0.25)), this->A, this->B, this->C, false);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->t, T(1));
}

// The area sum exceeds ABC by 2 area(PAB) = |y| here: accepted up to epsilon3.
TYPED_TEST(DocumentMethod, AreasEpsilon3AcceptsPointsOutside) {
  using T = TypeParam;
  EXPECT_TRUE(hits<T>("areas", this->down(T(0.5), T(-3e-4)), this->A, this->B, this->C));
  EXPECT_FALSE(hits<T>("areas", this->down(T(0.5), T(-3e-3)), this->A, this->B, this->C));
}

// Hits at t <= epsilon5 are dropped whatever the ray's tmin.
TYPED_TEST(DocumentMethod, AreasRejectsHitsNearerThanEpsilon5) {
  using T = TypeParam;
  const auto near = this->down(T(0.25), T(0.25), T(5e-6));
  EXPECT_FALSE(hits<T>("areas", near, this->A, this->B, this->C));
  EXPECT_TRUE(hits<T>("moller", near, this->A, this->B, this->C));
  EXPECT_TRUE(hits<T>("areas", this->down(T(0.25), T(0.25), T(2e-5)), this->A, this->B, this->C));
}

// epsilon5 is a distance (the document's direction is unit): a direction of
// length 1000 with t = 5e-6 travels 5e-3 and is kept; t = 5e-9 travels 5e-6
// and is dropped.
TYPED_TEST(DocumentMethod, AreasEpsilon5IsADistanceWhateverTheDirectionLength) {
  using T = TypeParam;
  using V = Vec3<T>;
  const Ray<T> far_enough{V{T(0.25), T(0.25), T(5e-3)}, V{0, 0, T(-1000)}};
  EXPECT_TRUE(hits<T>("areas", far_enough, this->A, this->B, this->C));
  const Ray<T> too_near{V{T(0.25), T(0.25), T(5e-6)}, V{0, 0, T(-1000)}};
  EXPECT_FALSE(hits<T>("areas", too_near, this->A, this->B, this->C));
}

// The listing's Heron bug: points on the line through B and C but beyond C
// (P = (1 - s, s), s in (1.5, 3)) are far outside, and the area sum PBC + APC
// + ABP = s is 1/2 + (s - 1) + ... > ABC + epsilon3 for all of them; yet where
// rounding makes PBC's Heron product negative, sqrt gives NaN, the comparison
// is false and the document accepts the point. Every accepted point must be
// such a NaN case, and some exist in both precisions.
// Heron's product p(p-a)(p-b)(p-c) as the listing writes it, in T: the
// cause of the NaN is that it rounds below zero.
template <class T>
T heron_product(const Vec3<T>& v1, const Vec3<T>& v2, const Vec3<T>& v3) {
  const T a = length(v2 - v1), b = length(v3 - v1), c = length(v3 - v2);
  const T p = (a + b + c) / T(2);
  return p * (p - a) * (p - b) * (p - c);
}

TYPED_TEST(DocumentMethod, AreasAcceptsPointsOnAnEdgeLineWhereHeronGivesNaN) {
  using T = TypeParam;
  using V = Vec3<T>;
  int accepted = 0;
  for (int i = 0; i < 2000; ++i) {
    const T s = T(1.5) + T(1.5) * T(i) / T(2000);
    const Ray<T> r = this->down(T(1) - s, s);
    if (!hits<T>("areas", r, this->A, this->B, this->C)) continue;
    ++accepted;
    EXPECT_TRUE(std::isnan(areas::area(V{T(1) - s, s, 0}, this->B, this->C))) << "s = " << s;
    EXPECT_LT(heron_product(V{T(1) - s, s, 0}, this->B, this->C), T(0)) << "s = " << s;
  }
  EXPECT_GT(accepted, 0) << "expected the listing's NaN acceptance to show on this line";
}

// |N.v| < 1e-6 with N and v unnormalised: a triangle with legs 1e-4 has
// |N| = 1e-8 and is "parallel" to a unit direction even head-on; a direction
// 1000x longer makes it visible again.
TYPED_TEST(DocumentMethod, SamesideParallelTestDependsOnScale) {
  using T = TypeParam;
  using V = Vec3<T>;
  const V a{0, 0, 0}, b{T(1e-4), 0, 0}, c{0, T(1e-4), 0};
  const Ray<T> unit{{T(2.5e-5), T(2.5e-5), 1}, {0, 0, -1}};
  EXPECT_FALSE(hits<T>("sameside", unit, a, b, c));
  EXPECT_TRUE(hits<T>("moller", unit, a, b, c));
  const Ray<T> longer{{T(2.5e-5), T(2.5e-5), 1}, {0, 0, -1000}};
  EXPECT_TRUE(hits<T>("sameside", longer, a, b, c));
}

// A ray starting on the plane (t = 0 with tmin = 0): the window admits it, but
// watertight's conservative bound (t > deltaT >= 0) never reports t = 0.
TYPED_TEST(DocumentMethod, WatertightNeverReportsZeroT) {
  using T = TypeParam;
  const auto on = this->down(T(0.25), T(0.25), T(0));
  EXPECT_TRUE(hits<T>("moller", on, this->A, this->B, this->C));
  EXPECT_FALSE(hits<T>("watertight", on, this->A, this->B, this->C));
}

TEST(DocumentConstants, KeepTheirDocumentsValues) {
  EXPECT_EQ(angles::PLUS_ZERO, 0.00001);
  EXPECT_EQ(angles::MINUS_ZERO, -0.0001);
  EXPECT_EQ(areas::epsilon5, 1e-5);
  EXPECT_EQ(areas::epsilon3, 1e-3);
  EXPECT_EQ(sameside::kParallel, 1e-6);
}

}  // namespace
}  // namespace ra
