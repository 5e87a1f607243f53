// `rayaudit audit diff A.json B.json`: is run B no worse than run A? Every
// method x precision x family x sweep value whose wrong count, leaks,
// double hits, NaN answers or t error rose (exit 1), improvements listed
// (exit 0 when nothing rose). A and B may be plain audits, merged shards or
// --grade outputs; runs of different rays (version, seed, --rays,
// families) are refused in one line (validation/baseline/baseline.h).
#include <memory>

#include "baseline/gate.h"
#include "command.h"
#include "errors.h"
#include "io/atomic_file.h"

namespace {

struct Args {
  std::string before, after, junit;
};

void diff(const Args& a) {
  ra::OutputBatch outputs({a.junit});
  const nlohmann::json before = ra::baseline::read_audit_json(a.before);
  const nlohmann::json after = ra::baseline::read_audit_json(a.after);
  const ra::baseline::GateResult g =
      ra::baseline::gate(after, before, {.baseline_name = a.before, .junit = a.junit, .suite = "rayaudit audit diff"});
  outputs.commit();
  if (g.rose)
    throw ra::CheckFailed("audit diff: " + a.after + " is worse than " + a.before + " (the rows marked ROSE)");
}

void setup(CLI::App& app) {
  // A subcommand of `audit` (cli/cmd_audit.cpp registers it first).
  CLI::App* audit = app.get_subcommand("audit");
  auto a = std::make_shared<Args>();
  auto* cmd = audit->add_subcommand(
      "diff", "Compare two audit --json files (A the baseline, B the new run): exit 1 if any figure rose");
  cmd->add_option("baseline", a->before, "The earlier audit's --json (plain, merged or --grade)")->required();
  cmd->add_option("current", a->after, "The new audit's --json")->required();
  cmd->add_option("--junit", a->junit, "Write JUnit XML: one test case per method x precision x family");
  cmd->callback([a] { diff(*a); });
}

ra::cli::Registrar reg(31, setup);

}  // namespace
