// The tracer audit (tracers.h): our accelerations answer as the loop over
// every triangle does, at every placement and scale; the watertight method
// through our BVH, Embree's robust mode and CGAL's AABB tree do not leak; a
// user's tracer that drops hits is caught by the GoogleTest assertion; an
// unknown tracer name lists the known ones.
#include "tracers/tracers_gtest.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "exact/oracle.h"

namespace ra::tracers {
namespace {

Options small() {
  Options o;
  o.rays = 200;
  return o;
}

TEST(Tracers, OurAccelerationsLeakAndHitAsTheLoopOverEveryTriangle) {
  for (const char* method : {"moller", "watertight", "baldwin"})
    for (const char* prec : {"float", "double"}) {
      const std::string m = std::string(method) + "/" + prec;
      std::vector<Subject> s = named("none:" + m);
      for (const char* a : {"bvh:", "sphere:"}) s.push_back(named(a + m)[0]);
      const Report r = run(s, small());
      for (std::size_t k = 1; k < s.size(); ++k) {
        const Stats a = r.total(0), b = r.total(k);
        EXPECT_EQ(a.leaks, b.leaks) << s[k].name;
        EXPECT_EQ(a.false_hits, b.false_hits) << s[k].name;
        EXPECT_EQ(a.wrong_nearest, b.wrong_nearest) << s[k].name;
      }
      EXPECT_GT(r.total(0).rays, 3000u);
    }
}

TEST(Tracers, WatertightThroughOurBvhEmbreeRobustAndCgalDoNotLeak) {
  EXPECT_TRACER_WATERTIGHT(named("bvh:watertight/double")[0]);
  EXPECT_TRACER_WATERTIGHT(named("bvh:watertight/float")[0]);
  EXPECT_TRUE(IsLeakFree(named("cgal-aabb")[0], small()));
  EXPECT_TRUE(IsLeakFree(named("embree-robust")[0], small()));
}

TEST(Tracers, TheAssertionCatchesAUserTracerThatDropsHits) {
  // A user's tracer: a loop over the triangles with the exact oracle (so
  // every crossing is found), which then drops the hits on triangle 0.
  struct Loop {
    Mesh m;
  };
  auto build = [](const Mesh& m) { return Loop{m}; };
  auto intersect = [](const Loop& l, const Rayd& r) -> std::optional<Hit> {
    std::optional<Hit> best;
    for (std::size_t i = 0; i < l.m.triangles.size(); ++i) {
      const auto& f = l.m.triangles[i];
      const oracle::Answer a = oracle::triangle(r, l.m.positions[std::size_t(f[0])], l.m.positions[std::size_t(f[1])],
                                                l.m.positions[std::size_t(f[2])]);
      if ((a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) && (!best || a.t < best->t))
        best = Hit{a.t, int(i)};
    }
    if (best && best->prim == 0) return std::nullopt;
    return best;
  };
  const Subject exact = tracer_subject<Loop>("exact-loop", Precision::f64, build,
                                             [&](const Loop& l, const Rayd& r) { return intersect(l, r); });
  EXPECT_TRUE(IsLeakFree(
      tracer_subject<Loop>("exact", Precision::f64, build,
                           [&](const Loop& l, const Rayd& r) {
                             std::optional<Hit> best;
                             for (std::size_t i = 0; i < l.m.triangles.size(); ++i) {
                               const auto& f = l.m.triangles[i];
                               const oracle::Answer a =
                                   oracle::triangle(r, l.m.positions[std::size_t(f[0])],
                                                    l.m.positions[std::size_t(f[1])], l.m.positions[std::size_t(f[2])]);
                               if ((a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) &&
                                   (!best || a.t < best->t))
                                 best = Hit{a.t, int(i)};
                             }
                             return best;
                           }),
      small()));
  const ::testing::AssertionResult r = IsLeakFree(exact, small());
  EXPECT_FALSE(r);
  EXPECT_NE(std::string(r.message()).find("exact-loop leaked"), std::string::npos) << r.message();
}

TEST(Tracers, UnknownNamesListTheKnownOnes) {
  for (const char* bad : {"embre", "bvh:nosuch", "bvh:moller/half", "embree:moller"}) {
    try {
      named(bad);
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("embree-robust"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(named("bvh").size(), 18u);  // 9 triangle methods, 2 precisions
}

}  // namespace
}  // namespace ra::tracers
