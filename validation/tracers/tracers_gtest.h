// A GoogleTest assertion over a whole tracer (tracers.h), beside
// EXPECT_WATERTIGHT (exact/audit_gtest.h) for a triangle test alone:
//   auto mine = ra::tracers::tracer_subject<MyBvh>("mine", ra::audit::Precision::f32, build, intersect);
//   EXPECT_TRACER_WATERTIGHT(mine);
//   EXPECT_TRUE(ra::tracers::IsLeakFree(mine, {.rays = 20000, .seed = 3}));
// Succeeds when no ray the exact answer sends into the closed meshes (from
// inside, or from outside through a vertex or an edge) passes through the
// tracer, at any placement and scale; the message names every cell that
// leaked and its inside miss rate against Embree's 2e-5 bar.
#pragma once
#include <gtest/gtest.h>

#include <sstream>

#include "tracers.h"

namespace ra::tracers {

inline ::testing::AssertionResult IsLeakFree(const Subject& s, const Options& o = {}) {
  const Report r = run({s}, o);
  std::ostringstream bad;
  const Stats t = r.total(0);
  if (t.rays == 0) return ::testing::AssertionFailure() << s.name << " was judged on no ray";
  for (const Cell& c : r.cells)
    if (c.stats.leaks)
      bad << " " << c.shape << "@offset " << c.offset << " scale " << c.scale << ": " << c.stats.leaks << "/"
          << c.stats.rays << " (inside miss rate "
          << double(c.stats.inside_leaks) / double(std::max<std::uint64_t>(1, c.stats.inside_rays)) << ", Embree's bar "
          << kEmbreeMissRate << ");";
  if (bad.str().empty()) return ::testing::AssertionSuccess() << s.name << " did not leak on " << t.rays << " rays";
  return ::testing::AssertionFailure() << s.name << " leaked " << t.leaks << " of " << t.rays << " rays (seed "
                                       << o.seed << "):" << bad.str();
}

}  // namespace ra::tracers

#define EXPECT_TRACER_WATERTIGHT(subject) EXPECT_TRUE(::ra::tracers::IsLeakFree(subject))
