// GoogleTest assertions over the audit (validation/exact/audit.h), so a user tests
// their own intersector against the exact oracle: EXPECT_WATERTIGHT(subject).
//
//   auto mine = ra::audit::triangle_subject<float>("mine", my_intersector);
//   EXPECT_WATERTIGHT(mine);                       // edge, vertex, closed-mesh
//   EXPECT_TRUE(ra::audit::IsWatertight(mine, {.rays = 50000, .seed = 7}));
//   EXPECT_TRUE(ra::audit::HasNoWrongAnswers(mine, {.families = {"random"}}));
//   EXPECT_TRUE(ra::audit::IsWatertight(mine, {.sweeps = {"0", "sphere@origin", "box@origin"}}));  // near the origin
//   EXPECT_TRUE(ra::audit::IsNoWorseThan(mine, "mine-baseline.json"));  // a regression gate
//
// A long audit spread over GoogleTest's own shards (GTEST_TOTAL_SHARDS=N,
// GTEST_SHARD_INDEX, as set by ctest, Bazel or a CI matrix): register it with
// RegisterShardedAudit; it becomes N tests NAME/shard_K_of_N, which
// GoogleTest deals one per shard, each judging 1/N of the rays (--shard K/N).
//   static const bool reg = ra::audit::RegisterShardedAudit("Mine", "Watertight",
//       [](const ra::audit::Shard& s) { EXPECT_TRUE(ra::audit::IsWatertight(mine(), {.rays = 10000000, .shard = s}));
//       });
// (A plain TEST runs on one shard only, so plain assertions judge every ray.)
// Header-only: include it from a test linked to GTest and rayaudit::validation.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>

#include "../baseline/baseline.h"
#include "audit.h"

namespace ra::audit {

struct CheckOptions {
  // Every member has an initializer, so a designated initializer that sets
  // only some ({.families = {...}}) draws no -Wmissing-field-initializers.
  std::vector<std::string> families{};  // empty: the assertion's own default
  long long rays = 20000;
  std::uint64_t seed = 1;
  int threads = 0;               // 0: all cores; the subject is called from that many threads at once
  std::optional<Shard> shard{};  // unset: every ray
  // Only these sweep values count (labels as the table prints them: "0",
  // "1e-06", "sphere@origin"); empty: all. Every family is still run.
  std::vector<std::string> sweeps{};
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
                            [body, k, n]() -> detail::ShardedAuditTest* {
                              return new detail::ShardedAuditTest(body, Shard{k, n});
                            });
  }
  return true;
}

inline Report run_check(const TriangleSubject& s, const CheckOptions& c, std::vector<std::string> default_families) {
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

// Whether a cell counts under c.sweeps; a label no run family has is a
// typo that would judge nothing, and throws std::invalid_argument.
inline bool in_sweeps(const CheckOptions& c, const Cell& cell) {
  return c.sweeps.empty() || std::find(c.sweeps.begin(), c.sweeps.end(), cell.sweep_label) != c.sweeps.end();
}
inline void check_sweeps(const CheckOptions& c, const Report& r) {
  for (const std::string& w : c.sweeps) {
    bool found = false;
    std::string all;
    for (const Cell& cell : r.cells) {
      found = found || cell.sweep_label == w;
      if (all.find(" " + cell.sweep_label + ",") == std::string::npos) all += " " + cell.sweep_label + ",";
    }
    if (!found)
      throw std::invalid_argument("audit: sweep value '" + w + "' is in none of the families run (" + all + ")");
  }
}

// The failing families' case ids, replay commands and hints (baseline.h).
inline std::string teaching_lines(const Report& r, const CheckOptions& c, const std::vector<std::string>& families) {
  ra::baseline::Scope scope;
  scope.families = families;
  scope.sweeps = c.sweeps;
  std::string lines = ra::baseline::failure_lines(ra::baseline::family_results(r.to_json(), scope));
  return lines.empty() ? "" : "\n" + lines;
}

// Succeeds when no ray the exact answer sends through an edge pair, a vertex
// fan or a closed mesh passes through the subject without a hit, and no hit
// there has a t that is NaN, infinite or off by more than 1% (a renderer
// drops such a hit, so the ray leaks all the same). The failure message
// names every family@sweep that leaked, with counts and the seed. A run
// that judged no group (every ray sharded away) fails too.
inline ::testing::AssertionResult IsWatertight(const TriangleSubject& s, const CheckOptions& c = {}) {
  const Report r = run_check(s, c, {"edge", "vertex", "closed-mesh"});
  check_sweeps(c, r);
  std::ostringstream leaked, bad_t;
  std::uint64_t leaks = 0, groups = 0, bad = 0;
  std::vector<std::string> failing;
  for (const Cell& cell : r.cells) {
    if (!in_sweeps(c, cell)) continue;
    groups += cell.stats.groups;
    if (cell.stats.leaks || cell.stats.wrong_t || cell.stats.nan_inf) failing.push_back(cell.family);
    if (cell.stats.leaks) {
      leaks += cell.stats.leaks;
      leaked << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.leaks << "/" << cell.stats.groups
             << ";";
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
  if (leaks)
    failure << s.name() << " leaked " << leaks << " of " << groups << " groups (seed " << c.seed << shard_note(c)
            << "):" << leaked.str();
  else
    failure << s.name() << " did not leak on " << groups << " groups (seed " << c.seed << shard_note(c) << ")";
  if (bad) failure << " and has " << bad << " hits with t NaN, infinite or off by more than 1%:" << bad_t.str();
  return failure << teaching_lines(r, c, failing);
}

// Succeeds when the subject has no false hit, false miss, wrong t or NaN on
// the families (default: random, grazing, offset, scale).
inline ::testing::AssertionResult HasNoWrongAnswers(const TriangleSubject& s, const CheckOptions& c = {}) {
  const Report r = run_check(s, c, {"random", "grazing", "offset", "scale"});
  check_sweeps(c, r);
  std::ostringstream bad;
  std::vector<std::string> failing;
  for (const Cell& cell : r.cells)
    if (in_sweeps(c, cell) && cell.stats.wrong() + cell.stats.nan_inf > 0) {
      bad << " " << cell.family << "@" << cell.sweep_label << ": " << cell.stats.false_hits << " false hits, "
          << cell.stats.false_misses << " false misses, " << cell.stats.wrong_t << " wrong t, " << cell.stats.nan_inf
          << " NaN;";
      failing.push_back(cell.family);
    }
  if (bad.str().empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << s.name() << " (seed " << c.seed << shard_note(c) << "):" << bad.str()
                                       << teaching_lines(r, c, failing);
}

// A regression gate: succeeds when no wrong count, leak count, double hit
// count or NaN count of the subject rose against `baseline_json` (an audit
// --json holding this subject, by name "METHOD/PRECISION"), and no t error
// maximum more than doubled; the failure is the table of what rose, with
// case ids and replay commands. Seed, rays per family and the families come
// from the baseline (c.families and c.sweeps narrow them; c.threads and
// c.shard apply; c.seed and c.rays are not used). With the environment
// variable RAYAUDIT_UPDATE_BASELINE=1 it writes this run there instead
// (the families of c, or every triangle family) and succeeds.
inline ::testing::AssertionResult IsNoWorseThan(const TriangleSubject& s, const std::string& baseline_json,
                                                const CheckOptions& c = {}) {
  const char* update = std::getenv("RAYAUDIT_UPDATE_BASELINE");
  if (update && std::string(update) == "1") {
    const Report r = run_check(s, c, {});
    std::ofstream out(baseline_json, std::ios::binary | std::ios::trunc);
    out << r.to_json().dump(1) << "\n";
    if (!out) return ::testing::AssertionFailure() << baseline_json << ": cannot write the baseline";
    return ::testing::AssertionSuccess() << "wrote the baseline " << baseline_json;
  }
  std::ifstream in(baseline_json, std::ios::binary);
  if (!in)
    return ::testing::AssertionFailure() << baseline_json
                                         << ": no baseline (run once with RAYAUDIT_UPDATE_BASELINE=1 "
                                            "to write it from this run, or give an audit --json)";
  nlohmann::json base;
  try {
    base = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << baseline_json << ": not JSON (" << e.what() << ")";
  }
  if (!base.is_object() || !base.contains("cells") || !base["cells"].is_array() || !base.contains("seed") ||
      !base["seed"].is_number_unsigned() || !base.contains("rays_per_family") ||
      !base["rays_per_family"].is_number_integer())
    return ::testing::AssertionFailure() << baseline_json << ": not an audit's JSON (no seed, rays_per_family, cells)";
  std::vector<std::string> families;
  for (const auto& cell : base["cells"])
    if (cell.value("subject", "") == s.name()) {
      const std::string f = cell.value("family", "");
      if ((c.families.empty() || std::find(c.families.begin(), c.families.end(), f) != c.families.end()) &&
          std::find(families.begin(), families.end(), f) == families.end())
        families.push_back(f);
    }
  if (families.empty())
    return ::testing::AssertionFailure() << baseline_json << " has no cell of " << s.name()
                                         << (c.families.empty() ? "" : " in the families asked for");
  CheckOptions run_opts = c;
  run_opts.families = families;
  run_opts.seed = base["seed"].get<std::uint64_t>();
  run_opts.rays = base["rays_per_family"].get<long long>();
  const Report r = run_check(s, run_opts, families);
  check_sweeps(c, r);
  ra::baseline::Scope scope;
  scope.subjects = {s.name()};
  scope.families = families;
  scope.sweeps = c.sweeps;
  try {
    const ra::baseline::Diff d = ra::baseline::compare(base, r.to_json(), scope);
    if (d.worse())
      return ::testing::AssertionFailure()
             << s.name() << " is worse than " << baseline_json << ": " << d.table(r.to_json());
    return ::testing::AssertionSuccess() << s.name() << " is no worse than " << baseline_json << ": "
                                         << d.table(r.to_json());
  } catch (const ra::baseline::Mismatch& e) {
    return ::testing::AssertionFailure() << baseline_json << ": cannot be " << s.name() << "'s baseline: " << e.what();
  }
}

}  // namespace ra::audit

#define EXPECT_WATERTIGHT(subject) EXPECT_TRUE(::ra::audit::IsWatertight(subject))
#define ASSERT_WATERTIGHT(subject) ASSERT_TRUE(::ra::audit::IsWatertight(subject))
