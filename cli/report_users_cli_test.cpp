// The report with a user's subjects beside the registry's: several --audit
// files of one seed and rays, the user's graded subject labelled in the
// charts and on the speed chart (its kernel timed into --timings), and the
// run's real seed and rays in the header.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::one_line;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path tmp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-report-users-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

TEST(ReportUsers, GradedSubjectIsLabelledOnTheSpeedChartBesideOurs) {
  const fs::path main = tmp("main.json"), cases = tmp("cases.csv"), answers = tmp("mine.csv"), graded = tmp("g.json"),
                 bench = tmp("bench.json"), timings = tmp("timings.csv"), out = tmp("rep");
  ASSERT_EQ(
      run_rayaudit("audit --methods moller --families edge,grazing --rays 1000 --seed 4 --json " + main.string()).code,
      0);
  ASSERT_EQ(run_rayaudit("audit --export-cases " + cases.string() +
                         " --families edge,grazing --rays 1000 --seed 4 --precision float")
                .code,
            0);
  // The user's answers: every case a miss (wrong, but graded all the same).
  {
    std::ifstream in(cases);
    std::ofstream a(answers);
    std::string line;
    std::getline(in, line), std::getline(in, line);
    a << "id,hit,t\n";
    while (std::getline(in, line)) a << line.substr(0, line.find(',')) << ",false,\n";
  }
  ASSERT_EQ(
      run_rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " + graded.string())
          .code,
      0);
  // Our kernel rows as `rayaudit bench` writes them, and the user's timing
  // (validation/baseline/timing.h writes this CSV; other languages too).
  std::ofstream(bench) << R"({"context": {"host_name": "h"}, "benchmarks": [
    {"name": "kernel/moller/float/nocull/hit=50/back=0/real_time", "run_type": "iteration", "ns_per_test": 6.5},
    {"name": "kernel/moller/double/nocull/hit=50/back=0/real_time", "run_type": "iteration", "ns_per_test": 7.0}]})";
  std::ofstream(timings) << "subject,ns_per_test\nmine/float,9.25\n";
  auto r = run_rayaudit("report --audit " + main.string() + " --audit " + graded.string() + " --bench " +
                        bench.string() + " --timings " + timings.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.all;
  const std::string page = slurp(out / "index.html");
  const auto rep = nlohmann::json::parse(slurp(out / "report.json"));
  bool timed = false;
  for (const auto& e : rep["speed_accuracy"])
    if (e["subject"] == "mine/float") timed = e["ns_per_test"] == 9.25;
  EXPECT_TRUE(timed) << rep["speed_accuracy"].dump();
  // Labelled on the speed chart (SVG text stays text) and in the legends.
  EXPECT_NE(page.find("yours: mine/f"), std::string::npos);
  EXPECT_NE(page.find("mine (yours)"), std::string::npos);
  EXPECT_NE(page.find(">moller/f<"), std::string::npos) << "ours beside it";
  // The run's real seed and rays, and which file holds which subject.
  EXPECT_NE(page.find("seed 4, 1000 ray/primitive tests"), std::string::npos);
  EXPECT_NE(page.find("g.json: mine/float"), std::string::npos);
  EXPECT_EQ(page.find("Most right: <b>mine"), std::string::npos);

  // A graded file alone: still the real seed, and no "most right" of one.
  r = run_rayaudit("report --audit " + graded.string() + " -o " + tmp("alone").string());
  ASSERT_EQ(r.code, 0) << r.all;
  const std::string alone = slurp(tmp("alone") / "index.html");
  EXPECT_NE(alone.find("seed 4, 1000 ray/primitive tests"), std::string::npos);
  EXPECT_EQ(alone.find("Most right"), std::string::npos);

  // Audits of other seeds are refused in one line.
  const fs::path other = tmp("other.json");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 1000 --seed 5 --json " + other.string()).code,
            0);
  r = run_rayaudit("report --audit " + main.string() + " --audit " + other.string() + " -o " + tmp("x").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("seed"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp("x")));
}

}  // namespace
