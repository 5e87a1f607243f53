// The tracer audit (tracers.h): our accelerations answer as the loop over
// every triangle does, at every placement and scale; the watertight method
// through our BVH, Embree's robust mode and CGAL's AABB tree do not leak; a
// user's tracer that drops hits is caught by the GoogleTest assertion; an
// unknown tracer name lists the known ones.
#include "tracers/tracers_gtest.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "exact/oracle.h"
#include "registry.h"

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
  // A user's tracer: a loop over the triangles with the exact oracle, so
  // every crossing is found and it passes; the same loop dropping the hits
  // on triangle 0 lets rays through and fails, naming itself.
  struct Loop {
    Mesh m;
  };
  auto build = [](const Mesh& m) { return Loop{m}; };
  auto loop_tracer = [&](const char* name, bool drop_triangle_0) {
    return tracer_subject<Loop>(
        name, Precision::f64, build, [drop_triangle_0](const Loop& l, const Rayd& r) -> std::optional<Hit> {
          std::optional<Hit> best;
          for (std::size_t i = 0; i < l.m.triangles.size(); ++i) {
            const auto& f = l.m.triangles[i];
            const oracle::Answer a =
                oracle::triangle(r, l.m.positions[std::size_t(f[0])], l.m.positions[std::size_t(f[1])],
                                 l.m.positions[std::size_t(f[2])]);
            if ((a.verdict == oracle::Verdict::hit || a.verdict == oracle::Verdict::boundary) &&
                (!best || a.t < best->t))
              best = Hit{a.t, int(i)};
          }
          if (drop_triangle_0 && best && best->prim == 0) return std::nullopt;
          return best;
        });
  };
  EXPECT_TRUE(IsLeakFree(loop_tracer("exact", false), small()));
  const ::testing::AssertionResult r = IsLeakFree(loop_tracer("exact-loop", true), small());
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
  // A bare accelerator names it over every triangle method of the registry,
  // in both precisions (a count written here went stale with each new method).
  std::vector<std::string> expected, got;
  for (const Method& m : methods())
    if (m.kind == Kind::triangle)
      for (const char* prec : {"float", "double"}) expected.push_back("bvh/" + m.name + "/" + prec);
  for (const Subject& s : named("bvh")) got.push_back(s.name);
  EXPECT_GE(expected.size(), 2u * 9u);
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace ra::tracers
