// GoogleTest assertions over the audit (validation/exact/audit.h), so a user tests
// their own intersector against the exact oracle: EXPECT_WATERTIGHT(subject).
//
//   auto mine = ra::audit::triangle_subject<float>("mine", my_intersector);
//   EXPECT_WATERTIGHT(mine);                       // edge, vertex, closed-mesh
//   EXPECT_TRUE(ra::audit::IsWatertight(mine, {.rays = 50000, .seed = 7}));
//   EXPECT_TRUE(ra::audit::HasNoWrongAnswers(mine, {.families = {"random"}}));
//
// A long audit spread over GoogleTest's own shards (GTEST_TOTAL_SHARDS=N,
// GTEST_SHARD_INDEX, as set by ctest, Bazel or a CI matrix): register it with
// RegisterShardedAudit; it becomes N tests NAME/shard_K_of_N, which
// GoogleTest deals one per shard, each judging 1/N of the rays (--shard K/N).
//   static const bool reg = ra::audit::RegisterShardedAudit("Mine", "Watertight",
//       [](const ra::audit::Shard& s) { EXPECT_TRUE(ra::audit::IsWatertight(mine(), {.rays = 10000000, .shard = s})); });
// (A plain TEST runs on one shard only, so plain assertions judge every ray.)
// Header-only: include it from a test linked to GTest and rayaudit::validation.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <optional>
#include <sstream>

#include "audit.h"

namespace ra::audit {

struct CheckOptions {
  // Every member has an initializer, so a designated initializer that sets
  // only some ({.families = {...}}) draws no -Wmissing-field-initializers.
  std::vector<std::string> families{};  // empty: the assertion's own default
  long long rays = 20000;
  std::uint64_t seed = 1;
  int threads = 0;  // 0: all cores; the subject is called from that many threads at once
  std::optional<Shard> shard{};         // unset: every ray
};

// GoogleTest's sharding variables as a Shard (index 0-based there, k 1-based
// here); unset, malformed or a single shard: nullopt.
inline std::optional<Shard> GTestShard() {
  const char* total = std::getenv("GTEST_TOTAL_SHARDS");
  const char* index = std::getenv("GTEST_SHARD_INDEX");
  if (!total || !index) return std::nullopt;
  char *e1 = nullptr, *e2 = nullptr;
  const long long n = std::strtoll(total, &e1, 10), i = std::strtoll(index, &e2, 10);
  if (*e1 || *e2 || n <= 1 || i < 0 || i >= n || std::uint64_t(n) > kMaxShards) return std::nullopt;
  return Shard{std::uint64_t(i) + 1, std::uint64_t(n)};
}

namespace detail {
class ShardedAuditTest : public ::testing::Test {
 public:
  ShardedAuditTest(std::function<void(const Shard&)> body, Shard s) : body_(std::move(body)), shard_(s) {}
  void TestBody() override { body_(shard_); }

 private:
  std::function<void(const Shard&)> body_;
  Shard shard_;
};
}  // namespace detail

// Registers `name` in `suite` once per GoogleTest shard: with
// GTEST_TOTAL_SHARDS = N, tests NAME/shard_K_of_N for K = 1..N, registered
// consecutively so GoogleTest (which runs test i on shard i mod N) gives each
// shard exactly one; without sharding, one test NAME with Shard{1, 1} (every
// ray). Call at namespace scope (static initialisation) or before RUN_ALL_TESTS.
inline bool RegisterShardedAudit(const char* suite, const char* name, std::function<void(const Shard&)> body,
                                 const char* file = __builtin_FILE(), int line = __builtin_LINE()) {
  const std::uint64_t n = GTestShard() ? GTestShard()->n : 1;
  for (std::uint64_t k = 1; k <= n; ++k) {
    const std::string test =
        n == 1 ? std::string(name) : std::string(name) + "/shard_" + std::to_string(k) + "_of_" + std::to_string(n);
    ::testing::RegisterTest(suite, test.c_str(), nullptr, nullptr, file, line,
                            [body, k, n]() -> detail::ShardedAuditTest* { return new detail::ShardedAuditTest(body, Shard{k, n}); });
  }
  return true;
}

inline Report run_check(const TriangleSubject& s, const CheckOptions& c,
                        std::vector<std::string> default_families) {
  Options o;
  o.families = c.families.empty() ? std::move(default_families) : c.families;
  o.rays = c.rays;
  o.seed = c.seed;
  o.threads = c.threads;
  o.shard = c.shard;
  return run({s}, {}, o);
}

inline std::string shard_note(const CheckOptions& c) {
  return c.shard ? ", shard " + std::to_string(c.shard->k) + "/" + std::to_string(c.shard->n) : "";
}

// Succeeds when no ray the exact answer sends through an edge pair, a vertex
// fan or a closed mesh passes through the subject without a hit, and no hit
// there has a t that is NaN, infinite or off by more than 1% (a renderer
// drops such a hit, so the ray leaks all the same). The failure message
// names every family@sweep that leaked, with counts and the seed. A run
// that judged no group (every ray sharded away) fails too.
inline ::testing::AssertionResult IsWatertight(const TriangleSubject& s, const CheckOptions& c = {}) {
  const Report r = run_check(s, c, {"edge", "vertex", "closed-mesh"});
  std::ostringstream leaked, bad_t;
  std::uint64_t leaks = 0, groups = 0, bad = 0;
  for (const Cell& cell : r.cells) {
    groups += cell.stats.groups;
    if (cell.stats.leaks) {
      leaks += cell.stats.leaks;
      leaked << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.leaks << "/"
             << cell.stats.groups << ";";
    }
    const std::uint64_t t = cell.stats.wrong_t + cell.stats.nan_inf;
    if (t) {
      bad += t;
      bad_t << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.wrong_t << " off, "
            << cell.stats.nan_inf << " NaN/inf;";
    }
  }
  if (groups == 0)
    return ::testing::AssertionFailure() << s.name() << " was judged on no group (seed " << c.seed << shard_note(c)
                                         << "): nothing shows it watertight";
  if (leaks == 0 && bad == 0)
    return ::testing::AssertionSuccess() << s.name() << " did not leak on " << groups << " groups";
  auto failure = ::testing::AssertionFailure();
  if (leaks) failure << s.name() << " leaked " << leaks << " of " << groups << " groups (seed " << c.seed << shard_note(c) << "):" << leaked.str();
  else failure << s.name() << " did not leak on " << groups << " groups (seed " << c.seed << shard_note(c) << ")";
  if (bad) failure << " and has " << bad << " hits with t NaN, infinite or off by more than 1%:" << bad_t.str();
  return failure;
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
  return ::testing::AssertionFailure() << s.name() << " (seed " << c.seed << shard_note(c) << "):" << bad.str();
}

}  // namespace ra::audit

#define EXPECT_WATERTIGHT(subject) EXPECT_TRUE(::ra::audit::IsWatertight(subject))
#define ASSERT_WATERTIGHT(subject) ASSERT_TRUE(::ra::audit::IsWatertight(subject))
