// Regression gates over audit JSON files: is this run no worse than the
// baseline (`rayaudit audit --baseline`, `rayaudit audit diff`,
// IsNoWorseThan in exact/audit_gtest.h), and what each failing family
// teaches (its case ids, the command that replays them, a one-sided hint).
//
// Why: a yes/no watertightness check cannot gate an intersector that was
// never watertight; users wrote scripts comparing CSV cells to ask "no
// worse than last release". validation/exact/README.md says what the
// counts mean. Guarantee: two runs are compared only when they judged the same
// rays (same rayaudit version, seed, rays per family, families and sweep
// values, and the same number of tests in every cell); otherwise Mismatch
// says which of these differs. Counts are deterministic for a seed, so a
// count rises only when an answer changed; the one maximum compared (the t
// error in ulps) counts as risen only when it more than doubles (plus 2
// ulps), so rounding that moves between compilers cannot flip the gate.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace ra::baseline {

// The cells a comparison or a check looks at; an empty list means all.
// Sweep values are the labels the JSON holds ("0", "1e-06", "sphere@origin").
struct Scope {
  std::vector<std::string> subjects, families, sweeps;
  bool has(const std::vector<std::string>& list, const std::string& v) const;
};

// Two audit files that cannot be compared: the one-line reason.
struct Mismatch : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One figure of one cell that moved.
struct Change {
  std::string subject, family, sweep;
  std::string measure;  // "wrong", "leaks", "double hits", "NaN answers", "t error (ulps, max)"
  double before = 0, after = 0;
};

struct Diff {
  std::vector<Change> rose, fell;
  std::vector<std::string> new_subjects;  // in the run, not in the baseline: not compared
  std::size_t cells = 0;                  // cells compared
  std::uint64_t seed = 0;
  long long rays = 0;
  std::string version;
  bool worse() const { return !rose.empty(); }
  // The rises (and improvements) as a table, then for each subject x family
  // that rose, up to 3 of its failing case ids and the command replaying them.
  std::string table(const nlohmann::json& current) const;
};

// Throws Mismatch when the two are not runs of the same rays (see above),
// or when a file is not an audit's output (a shard, an `audit --cases` table).
Diff compare(const nlohmann::json& baseline, const nlohmann::json& current, const Scope& scope = {});

// What must match before a run starts (so an hour's audit is not wasted):
// the baseline's version, seed and rays per family against the planned ones.
void check_plan(const nlohmann::json& baseline, std::uint64_t seed, long long rays);

// ---------------------------------------------------- failures that teach --
// One subject x family of an audit JSON, as the failure lines and JUnit show it.
struct FamilyResult {
  std::string subject, family;
  std::uint64_t tests = 0;
  bool failed = false;           // a wrong answer, leak, double hit or NaN answer in any sweep value
  std::string words;             // "grazing@1e-06: 12 false misses; grazing@1e-07: 40 false misses, 2 bad t"
  std::vector<std::string> ids;  // up to 3 failing case ids (the cells' "examples")
  std::string replay;            // a command showing those cases with their exact verdicts
  std::string hint;              // e.g. the subject looks one-sided; empty if nothing to say
};

std::vector<FamilyResult> family_results(const nlohmann::json& audit, const Scope& scope = {});

// The command that replays `ids` of `family` for `subject` (see family_results).
std::string replay_command(const nlohmann::json& audit, const std::string& subject, const std::string& family,
                           const std::vector<std::string>& ids);

// One block per failed result: its words, case ids, replay command and hint.
std::string failure_lines(const std::vector<FamilyResult>& results);

}  // namespace ra::baseline
