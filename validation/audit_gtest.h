// GoogleTest assertions over the audit (validation/audit.h), so a user tests
// their own intersector against the exact oracle: EXPECT_WATERTIGHT(subject).
//
//   auto mine = ra::audit::triangle_subject<float>("mine", my_intersector);
//   EXPECT_WATERTIGHT(mine);                       // edge, vertex, closed-mesh
//   EXPECT_TRUE(ra::audit::IsWatertight(mine, {.rays = 50000, .seed = 7}));
//   EXPECT_TRUE(ra::audit::HasNoWrongAnswers(mine, {.families = {"random"}}));
// Header-only: include it from a test linked to GTest and rayaudit::validation.
#pragma once
#include <gtest/gtest.h>

#include <sstream>

#include "audit.h"

namespace ra::audit {

struct CheckOptions {
  std::vector<std::string> families;  // empty: the assertion's own default
  long long rays = 20000;
  std::uint64_t seed = 1;
  int threads = 0;
};

inline Report run_check(const TriangleSubject& s, const CheckOptions& c,
                        std::vector<std::string> default_families) {
  Options o;
  o.families = c.families.empty() ? std::move(default_families) : c.families;
  o.rays = c.rays;
  o.seed = c.seed;
  o.threads = c.threads;
  return run({s}, {}, o);
}

// Succeeds when no ray the exact answer sends through an edge pair, a vertex
// fan or a closed mesh passes through the subject without a hit. The failure
// message names every family@sweep that leaked, with counts and the seed.
inline ::testing::AssertionResult IsWatertight(const TriangleSubject& s, const CheckOptions& c = {}) {
  const Report r = run_check(s, c, {"edge", "vertex", "closed-mesh"});
  std::ostringstream bad;
  std::uint64_t leaks = 0, groups = 0;
  for (const Cell& cell : r.cells) {
    groups += cell.stats.groups;
    if (cell.stats.leaks == 0) continue;
    leaks += cell.stats.leaks;
    bad << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.leaks << "/"
        << cell.stats.groups << ";";
  }
  if (leaks == 0)
    return ::testing::AssertionSuccess() << s.name() << " did not leak on " << groups << " groups";
  return ::testing::AssertionFailure() << s.name() << " leaked " << leaks << " of " << groups
                                       << " groups (seed " << c.seed << "):" << bad.str();
}

// Succeeds when the subject has no false hit, false miss, wrong t or NaN on
// the families (default: random, grazing, offset, scale).
inline ::testing::AssertionResult HasNoWrongAnswers(const TriangleSubject& s, const CheckOptions& c = {}) {
  const Report r = run_check(s, c, {"random", "grazing", "offset", "scale"});
  std::ostringstream bad;
  for (const Cell& cell : r.cells)
    if (cell.stats.wrong() + cell.stats.nan_inf > 0)
      bad << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.false_hits
          << " false hits, " << cell.stats.false_misses << " false misses, " << cell.stats.wrong_t
          << " wrong t, " << cell.stats.nan_inf << " NaN;";
  if (bad.str().empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << s.name() << " (seed " << c.seed << "):" << bad.str();
}

}  // namespace ra::audit

#define EXPECT_WATERTIGHT(subject) EXPECT_TRUE(::ra::audit::IsWatertight(subject))
#define ASSERT_WATERTIGHT(subject) ASSERT_TRUE(::ra::audit::IsWatertight(subject))
