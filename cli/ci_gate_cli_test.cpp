// The copyable CI files (examples/ci/) and the script they call
// (ci/audit-gate.sh) cannot rot: the YAML parses and calls only the
// script's steps, and the script runs every step from a fresh clone with
// a small --rays, gating a second run on the baseline the first one wrote.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>

#include "junit_xml.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::read_junit;
using ra::test::slurp;

namespace {

int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

TEST(CiFiles, YamlParsesAndCallsOnlyTheScriptsSteps) {
  for (const char* file : {"examples/ci/github-actions.yml", "examples/ci/gitlab-ci.yml"}) {
    const fs::path p = fs::path(RAYAUDIT_SOURCE_DIR) / file;
    // python3-yaml (ci/install-deps.sh): a real YAML parser.
    EXPECT_EQ(sh("/usr/bin/python3 -c \"import sys, yaml; d = yaml.safe_load(open(sys.argv[1])); "
                 "assert isinstance(d, dict) and d\" " +
                 p.string()),
              0)
        << file << " does not parse as YAML";
    const std::string text = slurp(p);
    const std::regex call("ci/audit-gate\\.sh ([a-z]+)");
    int calls = 0;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), call); it != std::sregex_iterator(); ++it) {
      const std::string step = (*it)[1];
      EXPECT_TRUE(step == "shard" || step == "merge" || step == "gate" || step == "report" || step == "all")
          << file << " calls an unknown step: " << step;
      ++calls;
    }
    EXPECT_GE(calls, 4) << file << " shards, merges, gates and reports through ci/audit-gate.sh";
  }
  // The GitHub matrix and GitLab's parallel jobs shard as the script expects.
  EXPECT_EQ(sh("/usr/bin/python3 -c \"import sys, yaml; d = yaml.safe_load(open(sys.argv[1])); "
               "assert d['jobs']['audit-shard']['strategy']['matrix']['shard'] == [1, 2, 3, 4]; "
               "assert d['jobs']['audit-gate']['needs'] == 'audit-shard'\" " +
               (fs::path(RAYAUDIT_SOURCE_DIR) / "examples/ci/github-actions.yml").string()),
            0);
  EXPECT_EQ(sh("/usr/bin/python3 -c \"import sys, yaml; d = yaml.safe_load(open(sys.argv[1])); "
               "assert d['audit-shard']['parallel'] == 4; "
               "assert d['audit-gate']['artifacts']['reports']['junit'] == 'audit-out/junit.xml'\" " +
               (fs::path(RAYAUDIT_SOURCE_DIR) / "examples/ci/gitlab-ci.yml").string()),
            0);
}

TEST(CiFiles, GateScriptRunsFromAFreshClone) {
  const fs::path src(RAYAUDIT_SOURCE_DIR);
  if (sh("git -C " + src.string() + " rev-parse HEAD >/dev/null 2>&1") != 0) GTEST_SKIP() << "not a git checkout";
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-ci-gate-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // The committed tree, as CI sees it: nothing of the build or of
  // uncommitted files.
  ASSERT_EQ(sh("git clone -q --no-checkout " + src.string() + " " + (dir / "clone").string() + " && git -C " +
               (dir / "clone").string() + " checkout -q $(git -C " + src.string() + " rev-parse HEAD)"),
            0);
  ASSERT_TRUE(fs::exists(dir / "clone" / "ci" / "audit-gate.sh")) << "commit ci/audit-gate.sh";
  const std::string env = "cd " + dir.string() + " && RAYAUDIT=" + std::string(RAYAUDIT_EXE) +
                          " AUDIT_RAYS=600 AUDIT_SHARDS=2 AUDIT_METHODS=moller,watertight AUDIT_FAMILIES=edge,grazing "
                          "AUDIT_BASELINE=base/audit-baseline.json AUDIT_OUT=out ";
  // First run: no baseline yet, so this run becomes it.
  ASSERT_EQ(sh(env + "AUDIT_REPORT=0 bash clone/ci/audit-gate.sh all > first.log 2>&1"), 0) << slurp(dir / "first.log");
  EXPECT_TRUE(fs::exists(dir / "base" / "audit-baseline.json"));
  EXPECT_NE(slurp(dir / "first.log").find("is now this run"), std::string::npos) << slurp(dir / "first.log");
  // Second run: gated on it, equal, passes; JUnit and the report written.
  ASSERT_EQ(sh(env + "bash clone/ci/audit-gate.sh all > second.log 2>&1"), 0) << slurp(dir / "second.log");
  EXPECT_NE(slurp(dir / "second.log").find("0 figure(s) rose"), std::string::npos) << slurp(dir / "second.log");
  const auto x = read_junit((dir / "out" / "junit.xml").string());
  ASSERT_TRUE(x.parsed) << x.cases;
  EXPECT_NE(x.cases.find("moller/float|edge|"), std::string::npos) << x.cases;
  EXPECT_NE(x.cases.find("watertight/double|grazing|"), std::string::npos) << x.cases;
  EXPECT_TRUE(fs::exists(dir / "out" / "report" / "index.html"));
  // Another seed against that baseline: refused in one line, exit 2.
  EXPECT_EQ(sh(env + "AUDIT_SEED=2 AUDIT_REPORT=0 bash clone/ci/audit-gate.sh all > third.log 2>&1"), 2)
      << slurp(dir / "third.log");
  fs::remove_all(dir);
}

}  // namespace
