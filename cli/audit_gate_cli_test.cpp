// Regression gates and CI outputs as a user runs them: audit --baseline,
// audit diff, --junit (read back with a real XML parser), the exported
// cases' stamp, families that cannot be exported, --ids replays.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "junit_xml.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::one_line;
using ra::test::read_junit;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path tmp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-gate-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// Answers from the exported exact verdicts themselves (hit and boundary
// cases hit at the exact t), less the first `lose` hits of `family`: an
// intersector that is right everywhere but there.
void write_answers(const fs::path& cases, const fs::path& answers, const std::string& family, int lose,
                   bool float_t = false) {
  std::ifstream in(cases);
  std::ofstream out(answers);
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line.rfind("# rayaudit-cases ", 0), 0u) << "the export's first line is its stamp: " << line;
  std::getline(in, line);
  const auto head = fields(line);
  const auto col = [&](const char* n) { return std::size_t(std::find(head.begin(), head.end(), n) - head.begin()); };
  const std::size_t id = col("id"), fam = col("family"), verdict = col("verdict"), t = col("t");
  ASSERT_LT(t, head.size());
  out << "id,hit,t\n";
  while (std::getline(in, line)) {
    const auto f = fields(line);
    bool hit = f[verdict] == "hit" || f[verdict] == "boundary";
    if (hit && f[verdict] == "hit" && f[fam] == family && lose > 0) --lose, hit = false;
    std::string tt = hit ? f[t] : "";
    if (hit && float_t) {  // what a float intersector answers: a float
      char buf[64];
      std::snprintf(buf, sizeof buf, "%a", double(float(std::strtod(f[t].c_str(), nullptr))));
      tt = buf;
    }
    out << f[id] << "," << (hit ? "true" : "false") << "," << tt << "\n";
  }
  ASSERT_EQ(lose, 0) << "fewer hits than asked to lose";
}

// A user's regression gate end to end: an intersector changed to lose 20 grazing hits fails
// --baseline with a table naming grazing; unchanged, it passes; the JUnit
// file parses and lists the failure.
TEST(AuditGate, LosingTwentyGrazingHitsFailsTheBaselineAndTheJUnitSaysWhere) {
  const fs::path cases = tmp("cases.csv"), base = tmp("base.json"), junit = tmp("gate.xml");
  fs::create_directories(tmp("v1")), fs::create_directories(tmp("v2"));
  const fs::path v1 = tmp("v1") / "mine.csv", v2 = tmp("v2") / "mine.csv";  // one subject name: "mine"
  auto r = run_rayaudit("audit --export-cases " + cases.string() +
                        " --families random,grazing --rays 2000 "
                        "--precision float --seed 5");
  ASSERT_EQ(r.code, 0) << r.all;
  write_answers(cases, v1, "grazing", 0);
  write_answers(cases, v2, "grazing", 20);
  // Graded as float from the stamp (no --precision), with its seed and rays.
  r = run_rayaudit("audit --grade " + v1.string() + " --cases " + cases.string() + " --json " + base.string());
  ASSERT_EQ(r.code, 0) << r.all;
  const auto j = nlohmann::json::parse(slurp(base));
  EXPECT_EQ(j["subjects"][0]["name"], "mine/float");
  EXPECT_EQ(j["seed"], 5);
  EXPECT_EQ(j["rays_per_family"], 2000);
  EXPECT_EQ(j["subjects"][0]["totals"]["wrong"], 0) << "the exact answers are right";

  // Unchanged: passes, and the JUnit file has every family passing.
  r = run_rayaudit("audit --grade " + v1.string() + " --cases " + cases.string() + " --baseline " + base.string() +
                   " --junit " + junit.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("0 figure(s) rose"), std::string::npos) << r.out;
  auto x = read_junit(junit.string());
  ASSERT_TRUE(x.parsed) << x.cases;
  EXPECT_EQ(x.cases, "mine/float|random|ok\nmine/float|grazing|ok\n");

  // 20 grazing hits lost: exit 1, a table naming grazing, the failure in JUnit.
  r = run_rayaudit("audit --grade " + v2.string() + " --cases " + cases.string() + " --baseline " + base.string() +
                   " --junit " + junit.string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("ROSE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mine/float"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("grazing@"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("random@"), std::string::npos) << "random did not change: " << r.out;
  // Case ids and the command that replays them.
  EXPECT_NE(r.out.find("cases grazing:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("replay: rayaudit audit --cases " + cases.string() + " --ids grazing:"), std::string::npos)
      << r.out;
  x = read_junit(junit.string());
  ASSERT_TRUE(x.parsed) << x.cases;
  EXPECT_NE(x.cases.find("mine/float|grazing|FAIL: rose against " + base.string() + ": grazing@"), std::string::npos)
      << x.cases;
  EXPECT_NE(x.cases.find("mine/float|random|ok"), std::string::npos) << x.cases;
  // The wrong answers, counted: 20 rose in all (over grazing's sweep values).
  std::uint64_t wrong = 0;
  for (std::size_t at = 0; (at = r.out.find("ROSE", at)) != std::string::npos; ++at) {
    const std::string row = r.out.substr(at, r.out.find('\n', at) - at);
    if (row.find(" wrong ") == std::string::npos) continue;
    const auto plus = row.rfind("(+");
    wrong += std::stoull(row.substr(plus + 2));
  }
  EXPECT_EQ(wrong, 20u) << r.out;

  // The same through `audit diff` of the two graded files.
  const fs::path worse = tmp("worse.json");
  ASSERT_EQ(
      run_rayaudit("audit --grade " + v2.string() + " --cases " + cases.string() + " --json " + worse.string()).code,
      0);
  r = run_rayaudit("audit diff " + base.string() + " " + worse.string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("grazing@"), std::string::npos) << r.out;
  r = run_rayaudit("audit diff " + worse.string() + " " + base.string());
  EXPECT_EQ(r.code, 0) << r.all << "better is not worse";
  EXPECT_NE(r.out.find("IMPROVED"), std::string::npos) << r.out;

  // The replay command shows exactly the ids named.
  const auto at = r.out.find("grazing:");
  (void)at;
  const auto ids = nlohmann::json::parse(slurp(worse))["cells"];
  std::string id;
  for (const auto& c : ids)
    if (c.contains("examples")) id = c["examples"][0];
  ASSERT_FALSE(id.empty());
  r = run_rayaudit("audit --cases " + cases.string() + " --ids " + id + " --precision float --methods moller");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("1 case(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(id), std::string::npos) << r.out;
  r = run_rayaudit("audit --cases " + cases.string() + " --ids grazing:nope:1");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
}

// Runs of other rays are refused in one line, before the work.
TEST(AuditGate, BaselinesOfOtherRaysAreRefusedInOneLine) {
  const fs::path a = tmp("a.json"), b = tmp("b.json"), shard = tmp("shard.json");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families grazing --rays 700 --json " + a.string()).code, 0);
  auto r = run_rayaudit("audit --methods moller --families grazing --rays 700 --baseline " + a.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("0 figure(s) rose"), std::string::npos) << r.out;
  const std::pair<std::string, std::string> refused[] = {{"--rays 700 --seed 2", "seed"},
                                                         {"--rays 800", "rays per family"}};
  for (const auto& [opt, word] : refused) {
    r = run_rayaudit("audit --methods moller --families grazing " + opt + " --baseline " + a.string());
    EXPECT_EQ(r.code, 2) << opt;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(word), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "refused before the run";
  }
  ASSERT_EQ(run_rayaudit("audit --methods moller --families random --rays 700 --json " + b.string()).code, 0);
  r = run_rayaudit("audit diff " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("families differ"), std::string::npos) << r.err;
  ASSERT_EQ(
      run_rayaudit("audit --methods moller --families grazing --rays 700 --shard 1/2 --json " + shard.string()).code,
      0);
  r = run_rayaudit("audit diff " + a.string() + " " + shard.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("merge the shards first"), std::string::npos) << r.err;
  // A version written into the file by another rayaudit.
  auto j = nlohmann::json::parse(slurp(a));
  j["version"] = "0.0.1";
  std::ofstream(b) << j.dump();
  r = run_rayaudit("audit diff " + b.string() + " " + a.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("rayaudit 0.0.1"), std::string::npos) << r.err;
}

// Merged shards compare as the unsharded run: equal, exit 0.
TEST(AuditGate, MergedShardsAreNoWorseThanTheWholeRun) {
  const fs::path whole = tmp("whole.json"), s1 = tmp("s1.json"), s2 = tmp("s2.json"), merged = tmp("merged.json");
  const std::string run = "audit --methods moller,watertight --precision float --families edge,grazing --rays 1500 ";
  ASSERT_EQ(run_rayaudit(run + "--json " + whole.string()).code, 0);
  ASSERT_EQ(run_rayaudit(run + "--shard 1/2 --json " + s1.string()).code, 0);
  ASSERT_EQ(run_rayaudit(run + "--shard 2/2 --json " + s2.string()).code, 0);
  ASSERT_EQ(run_rayaudit("audit merge " + s1.string() + " " + s2.string() + " --json " + merged.string()).code, 0);
  EXPECT_EQ(slurp(whole), slurp(merged)) << "failing case ids merge as the whole run names them";
  const auto r = run_rayaudit("audit diff " + whole.string() + " " + merged.string());
  EXPECT_EQ(r.code, 0) << r.all;
}

// A family that cannot be exported is refused by name; nothing is written.
TEST(AuditGate, FamiliesThatCannotBeExportedAreRefusedByName) {
  const fs::path out = tmp("refused.csv");
  auto r = run_rayaudit("audit --export-cases " + out.string() + " --families edge,secondary,huge --rays 10");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("'secondary'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = run_rayaudit("audit --export-cases " + out.string() + " --families edge,huge --rays 10");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("'huge' is a sphere family"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// Float answers to unstamped float cases: refused, never graded as double;
// a stamp from another version: refused.
TEST(AuditGate, FloatLookingAnswersNeedAPrecisionAndStampsAreChecked) {
  const fs::path cases = tmp("f_cases.csv"), plain = tmp("f_plain.csv"), answers = tmp("f_answers.csv");
  ASSERT_EQ(
      run_rayaudit("audit --export-cases " + cases.string() + " --families random --rays 300 --precision float").code,
      0);
  write_answers(cases, answers, "random", 0, /*float_t=*/true);
  // The same cases without their stamp line.
  {
    std::ifstream in(cases);
    std::ofstream out(plain);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) out << line << "\n";
  }
  auto r = run_rayaudit("audit --grade " + answers.string() + " --cases " + plain.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--precision float"), std::string::npos) << r.err;
  r = run_rayaudit("audit --grade " + answers.string() + " --cases " + plain.string() + " --precision float");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("f_answers/float"), std::string::npos) << r.out;
  // A stamp from another version.
  std::string text = slurp(cases);
  text.replace(text.find("version=") + 8, text.find(' ', text.find("version=")) - text.find("version=") - 8, "0.0.1");
  std::ofstream(plain) << text;
  r = run_rayaudit("audit --grade " + answers.string() + " --cases " + plain.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind(plain.string() + ":1: exported by rayaudit 0.0.1", 0), 0u) << r.err;
}

// golden check --junit: one test case per scene, failing with its message.
TEST(AuditGate, GoldenCheckWritesJUnit) {
  const fs::path root = tmp("golden-repo"), junit = tmp("golden.xml");
  fs::remove_all(root);
  fs::create_directories(root / "scenes");
  for (const char* n : {"a", "b"})
    std::ofstream(root / "scenes" / (std::string(n) + ".json"))
        << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}, "material": {"color": )"
        << (n[0] == 'a' ? "0.5" : "0.25") << "}}]}\n";
  ASSERT_EQ(run_rayaudit("golden bless --root " + root.string()).code, 0);
  fs::copy_file(root / "golden" / "b.png", root / "golden" / "a.png", fs::copy_options::overwrite_existing);
  const auto r = run_rayaudit("golden check --root " + root.string() + " --diff-dir " + tmp("gdiff").string() +
                              " --junit " + junit.string());
  EXPECT_EQ(r.code, 1) << r.all;
  const auto x = read_junit(junit.string());
  ASSERT_TRUE(x.parsed) << x.cases;
  EXPECT_EQ(x.cases.rfind("golden|a|FAIL: ", 0), 0u) << x.cases;
  EXPECT_NE(x.cases.find("golden|b|ok"), std::string::npos) << x.cases;
}

// compare --junit: one test case for the scene, judged as the exit code is.
TEST(AuditGate, CompareWritesJUnit) {
  const fs::path junit = tmp("compare.xml");
  const std::string scene = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/sphere-on-plane.json";
  const auto r = run_rayaudit("compare " + scene + " --width 16 --height 12 --junit " + junit.string());
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.all;
  const auto x = read_junit(junit.string());
  ASSERT_TRUE(x.parsed) << x.cases;
  EXPECT_EQ(x.cases.rfind("compare|" + scene + (r.code == 0 ? "|ok" : "|FAIL: "), 0), 0u) << x.cases << r.out;
}

}  // namespace
