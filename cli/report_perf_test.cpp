// The performance report: `rayaudit bench` records each row's spread and a
// calibration beside every repetition; `rayaudit report --bench A --bench B`
// (no audit needed) combines runs, flags a slowed row or a slow run, and draws
// ratios on a log axis centred on 1x with bars from 1x. No timing is asserted:
// the slowed inputs are real runs with figures scaled here, so the expected
// verdicts do not depend on the machine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "run_rayaudit.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ra::test::run_rayaudit;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-perf-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

json load(const fs::path& f) {
  std::ifstream in(f);
  return json::parse(in);
}

void save(const fs::path& f, const json& j) { std::ofstream(f) << j.dump(1); }

// A row's figures (ns per test) over the repetitions its median is taken
// over: those not marked slow, or all of them when every one was.
std::vector<double> used_figures(const json& bench, const std::string& row) {
  std::vector<double> normal, all;
  for (const json& b : bench.at("benchmarks"))
    if (b.at("run_type") == "iteration" && b.at("run_name") == row) {
      const double v = b.at("ns_per_test").get<double>();
      all.push_back(v);
      if (!b.at("rayaudit_slow_phase").get<bool>()) normal.push_back(v);
    }
  return normal.empty() ? all : normal;
}

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

const char* const kRows = "'^kernel/(moller|watertight)/float/nocull/hit=(0|50|100)/back=0$'";

// A real small kernel run: six rows, three repetitions each.
json bench_run(const fs::path& out, const std::string& extra = "") {
  const auto r = run_rayaudit("bench --quick --benchmark_repetitions=3 --benchmark_min_time=0.001 --filter " +
                              std::string(kRows) + " --json " + out.string() + " " + extra);
  EXPECT_EQ(r.code, 0) << r.all;
  return load(out);
}

TEST(BenchSpread, EveryRowHasItsRepetitionsCalibrationAndSpread) {
  const fs::path d = fresh_dir("spread");
  const json j = bench_run(d / "b.json");
  const json& ra = j.at("rayaudit");
  EXPECT_EQ(ra.at("mode"), "quick");
  EXPECT_EQ(ra.at("rounds"), 3);
  EXPECT_FALSE(ra.at("machine").at("cpu_model").get<std::string>().empty());
  ASSERT_EQ(ra.at("rows").size(), 6u);
  // Every repetition is an iteration row of its own, with the calibration
  // timed just before and just after it.
  std::map<std::string, int> reps;
  std::set<int> rounds;
  for (const json& b : j.at("benchmarks"))
    if (b.at("run_type") == "iteration") {
      ++reps[b.at("run_name").get<std::string>()];
      rounds.insert(b.at("rayaudit_round").get<int>());
      EXPECT_GT(b.at("rayaudit_cal_before_us").get<double>(), 0) << b.dump();
      EXPECT_GT(b.at("rayaudit_cal_after_cpu_us").get<double>(), 0) << b.dump();
    }
  EXPECT_EQ(reps.size(), 6u);
  for (const auto& [name, n] : reps) EXPECT_GE(n, 3) << name;
  for (int r : {0, 1, 2}) EXPECT_TRUE(rounds.count(r)) << r;
  // A sample before each round and one after every row of it.
  EXPECT_GE(ra.at("calibration").at("samples").size(), 3u * 7u);
  for (const json& e : ra.at("rows")) {
    EXPECT_EQ(e.at("metric"), "ns_per_test");
    const double lo = e.at("min"), q1 = e.at("q1"), med = e.at("median"), q3 = e.at("q3"), hi = e.at("max");
    EXPECT_TRUE(lo <= q1 && q1 <= med && med <= q3 && q3 <= hi) << e.dump();
    EXPECT_GT(lo, 0) << e.dump();
    // The median is one of the figures of the repetitions it is taken over
    // or between two of them: those at normal speed, or all of them when a
    // slow phase of this shared host marked every one slow.
    const std::vector<double> used = used_figures(j, e.at("name"));
    ASSERT_FALSE(used.empty()) << e.dump();
    const auto below = std::count_if(used.begin(), used.end(), [&](double v) { return v <= med; });
    const auto above = std::count_if(used.begin(), used.end(), [&](double v) { return v >= med; });
    EXPECT_GE(below, 1) << e.dump();
    EXPECT_GE(above, 1) << e.dump();
  }
  // compare.py's aggregates, as Google Benchmark names them, for every row
  // with two repetitions or more to take them over (a row left with one at
  // normal speed after the reruns has none, rather than a spread of one).
  std::set<std::string> aggs;
  for (const json& b : j.at("benchmarks"))
    if (b.at("run_type") == "aggregate") aggs.insert(b.at("name").get<std::string>());
  int rows_with_aggregates = 0;
  for (const json& e : ra.at("rows")) {
    const std::string name = e.at("name");
    const bool expected = used_figures(j, name).size() >= 2;
    rows_with_aggregates += expected;
    EXPECT_EQ(aggs.count(name + "_median"), expected ? 1u : 0u) << name;
    EXPECT_EQ(aggs.count(name + "_cv"), expected ? 1u : 0u) << name;
  }
  EXPECT_GE(rows_with_aggregates, 1) << "three repetitions of six rows, yet none had two to aggregate";
}

TEST(BenchSpread, RunsAreSeparateProcessesInOneJson) {
  const fs::path d = fresh_dir("runs");
  const auto r = run_rayaudit(
      "bench --quick --runs 2 --benchmark_repetitions=2 --benchmark_min_time=0.001 "
      "--filter '^kernel/moller/float/nocull/hit=50/back=0$' --json " +
      (d / "b.json").string());
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("run 2 of 2"), std::string::npos) << r.out;
  const json j = load(d / "b.json");
  EXPECT_EQ(j.at("rayaudit").at("runs"), 2);
  ASSERT_EQ(j.at("rayaudit").at("rows").size(), 1u);
  // Each run (a process of its own) gave its two repetitions, and any rerun
  // of a row it found too slow (marked rayaudit_retry); a run's median is
  // listed when it had a repetition at normal speed (a slow phase of this
  // shared host may mark all of one run's repetitions slow, and those are
  // left out of the figures).
  std::map<int, int> reps_of_run;
  std::set<int> normal_speed_runs;
  for (const json& b : j.at("benchmarks"))
    if (b.at("run_type") == "iteration") {
      if (!b.at("rayaudit_retry").get<bool>()) ++reps_of_run[b.at("rayaudit_run").get<int>()];
      if (!b.at("rayaudit_slow_phase").get<bool>()) normal_speed_runs.insert(b.at("rayaudit_run").get<int>());
    }
  EXPECT_EQ(reps_of_run, (std::map<int, int>{{0, 2}, {1, 2}}));
  std::set<int> median_runs;
  for (const json& m : j.at("rayaudit").at("rows")[0].at("run_medians")) median_runs.insert(m.at("run").get<int>());
  if (normal_speed_runs.empty()) normal_speed_runs = {0, 1};  // all slow: the figures come from the slow ones
  EXPECT_EQ(median_runs, normal_speed_runs);
  std::set<int> runs;
  for (const json& c : j.at("rayaudit").at("calibration").at("samples")) runs.insert(c.at("run").get<int>());
  EXPECT_EQ(runs, (std::set<int>{0, 1}));
}

// One real run b, and copies of it: a with every figure x0.9 (another run
// of the same rows, at the same calibration), c with one row slowed (its
// figures 1.6 times b's median where a's are 0.9 times it) and s with the whole run slowed
// (figures and calibration x1.4, as a slow phase does). Two real runs would
// make the verdicts depend on this shared host: a second run whose
// calibration came out 15% slower than the first is left out as slow.
TEST(ReportPerf, CombinesRunsFlagsASlowedRowAndLeavesOutASlowRun) {
  const fs::path d = fresh_dir("combine");
  const json b = bench_run(d / "b.json");
  json a = b;
  for (json& r : a.at("benchmarks"))
    if (r.at("run_type") == "iteration") r["ns_per_test"] = r.at("ns_per_test").get<double>() * 0.9;
  // The slowed row's repetitions, in a and in c, are its median in b times
  // 0.9 and 1.6, each 5% apart: b's own repetitions may spread further than
  // 1.6 / 0.9 on a loaded host (a burst inside one repetition, which the
  // calibration beside it does not see), and then the two runs' figures
  // overlap and rightly are not flagged.
  const std::string slowed_row = "kernel/watertight/float/nocull/hit=50/back=0";
  const double slowed_median = median_of(used_figures(b, slowed_row));
  auto set_slowed = [&](json& run, double factor) {
    int i = 0;
    for (json& r : run.at("benchmarks"))
      if (r.value("run_name", "") == slowed_row && r.at("run_type") == "iteration")
        r["ns_per_test"] = slowed_median * factor * (1 + 0.05 * i++);
  };
  set_slowed(a, 0.9);
  save(d / "a.json", a);
  json c = b;
  set_slowed(c, 1.6);
  save(d / "c.json", c);
  json s = b;
  for (json& r : s.at("benchmarks"))
    if (r.at("run_type") == "iteration") r["ns_per_test"] = r.at("ns_per_test").get<double>() * 1.4;
  for (json& x : s.at("rayaudit").at("calibration").at("samples"))
    x["us"] = x.at("us").get<double>() * 1.4, x["cpu_us"] = x.at("cpu_us").get<double>() * 1.4;
  save(d / "s.json", s);

  auto report = [&](const std::string& benches, const std::string& name) {
    const auto r = run_rayaudit("report " + benches + " -o " + (d / name).string());
    EXPECT_EQ(r.code, 0) << r.all;
    return load(d / name / "report.json");
  };
  auto row = [](const json& rep, const std::string& name) {
    for (const json& e : rep.at("bench").at("rows"))
      if (e.at("name") == name) return e;
    return json();
  };
  // The slowed row is flagged: its runs disagree beyond their spread.
  const json rc = report("--bench " + (d / "a.json").string() + " --bench " + (d / "c.json").string(), "rc");
  const json flagged = row(rc, slowed_row);
  ASSERT_FALSE(flagged.is_null());
  EXPECT_NE(flagged.at("flagged").get<std::string>().find("runs disagree"), std::string::npos) << flagged.dump();
  EXPECT_EQ(rc.at("bench").at("runs").size(), 2u);
  EXPECT_FALSE(rc.at("have_audit"));

  // The slow run is named and left out: each row's figure is then from a
  // and b alone, the median of their two medians: 0.95 of b's median (0.9
  // or 1 of it if a or b were dropped, 1.4 of it from s).
  const json rs = report("--bench " + (d / "a.json").string() + " --bench " + (d / "b.json").string() + " --bench " +
                             (d / "s.json").string(),
                         "rs");
  const json& runs = rs.at("bench").at("runs");
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_TRUE(runs[2].at("slow")) << runs.dump();
  EXPECT_EQ(rs.at("bench").at("used_runs"), json({0, 1}));
  const std::string probe = "kernel/moller/float/nocull/hit=0/back=0";
  const double expected = 0.95 * median_of(used_figures(b, probe));
  EXPECT_NEAR(row(rs, probe).at("median").get<double>(), expected, 1e-9 * expected);
  EXPECT_NE(row(rs, probe).at("flagged").get<std::string>().find("left out slow run(s): s.json"), std::string::npos);
  // The kernel chart's y axis starts at 0 and holds every range.
  bool kernel_chart = false;
  for (const json& ch : rs.at("charts"))
    if (ch.at("chart").get<std::string>().rfind("kernel_hit_rate/", 0) == 0) {
      kernel_chart = true;
      EXPECT_EQ(ch.at("ylim")[0].get<double>(), 0.0) << ch.dump();
      for (const json& e : rs.at("bench").at("rows"))
        EXPECT_LE(e.at("max").get<double>(), ch.at("ylim")[1].get<double>());
    }
  EXPECT_TRUE(kernel_chart);
  const std::string html = [&] {
    std::ifstream in(d / "rs" / "index.html");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }();
  EXPECT_NE(html.find("No audit given"), std::string::npos);
  EXPECT_NE(html.find("quick mode, 3 repetitions x 3 run(s)"), std::string::npos);
  EXPECT_NE(html.find("slow phase: left out of the medians"), std::string::npos);

  // Runs of unequal length (reruns, another --benchmark_repetitions): one
  // repetition at 10 against three at 1. The row's figure, the median of
  // the two runs' medians, is 5.5; the quartiles of the four pooled
  // repetitions are 1 and 3.25: the figure lies above them, and the report
  // still draws it.
  // b's row may hold reruns beside its three rounds: keep exactly `n` of
  // its repetitions, each at `ns`, at normal speed.
  auto with_reps = [&](int n, double ns) {
    json out = b;
    json kept = json::array();
    int k = 0;
    for (json r : b.at("benchmarks")) {
      if (r.value("run_name", "") == probe && r.at("run_type") == "iteration") {
        if (k++ >= n) continue;
        r["ns_per_test"] = ns;
        r["rayaudit_slow_phase"] = false;
      }
      kept.push_back(r);
    }
    EXPECT_GE(k, n);
    out["benchmarks"] = kept;
    return out;
  };
  const json one = with_reps(1, 10.0), three = with_reps(3, 1.0);
  save(d / "one.json", one);
  save(d / "three.json", three);
  const json ru = report("--bench " + (d / "one.json").string() + " --bench " + (d / "three.json").string(), "ru");
  const json pr = row(ru, probe);
  ASSERT_FALSE(pr.is_null());
  EXPECT_DOUBLE_EQ(pr.at("median").get<double>(), 5.5) << pr.dump();
  EXPECT_DOUBLE_EQ(pr.at("q3").get<double>(), 3.25) << pr.dump();
}

// Scene and peer rows as a bench writes them (three repetitions each), with
// chosen rates: the speed-up and peer charts' axes are centred on 1x, hold
// every bar and error bar, start the bars at 1x, print no label over another,
// and chart no culling of shadow rays.
TEST(ReportPerf, RatioChartsAreCentredOnOneXWithBarsFromIt) {
  const fs::path d = fresh_dir("ratio");
  json benchmarks = json::array();
  auto rep = [&](const std::string& name, const json& figures) {
    for (int i = 0; i < 3; ++i) {
      json r = {{"name", name},
                {"run_name", name},
                {"run_type", "iteration"},
                {"repetitions", 3},
                {"repetition_index", i},
                {"threads", 1},
                {"iterations", 1},
                {"real_time", 1.0},
                {"cpu_time", 1.0},
                {"time_unit", "ns"},
                {"rayaudit_slow_phase", false}};
      for (auto it = figures.begin(); it != figures.end(); ++it)
        r[it.key()] = it.value().get<double>() * (1 + 0.01 * (i - 1));
      benchmarks.push_back(r);
    }
  };
  for (const char* rays : {"primary", "shadow"})
    for (const std::string mesh : {"box", "bunny"}) {
      const double tris = mesh == "box" ? 12 : 69666, rays_n = 4096;
      rep("scene/" + mesh + "/none/nocull/" + rays + "/threads=1",
          {{"Mrays_per_s", 1.0}, {"triangles", tris}, {"rays", rays_n}});
      rep("scene/" + mesh + "/bvh/nocull/" + rays + "/threads=1",
          {{"Mrays_per_s", 850.0}, {"triangles", tris}, {"rays", rays_n}});
      rep("scene/" + mesh + "/bvh/cull/" + rays + "/threads=1",
          {{"Mrays_per_s", 900.0}, {"triangles", tris}, {"rays", rays_n}});
    }
  rep("peer/embree/bunny/primary/default/threads=1", {{"ratio", 0.9}, {"rays", 4096.0}});
  rep("peer/cgal/bunny/primary/threads=1", {{"ratio", 1.006}, {"rays", 4096.0}});
  rep("peer/pov/bunny/threads=1", {{"ratio", 3.2}});
  const json bench = {{"context", {{"num_cpus", 2}}},
                      {"benchmarks", benchmarks},
                      {"rayaudit", {{"mode", "quick"}, {"rounds", 3}, {"runs", 1}}}};
  save(d / "b.json", bench);
  const auto r = run_rayaudit("report --bench " + (d / "b.json").string() + " -o " + (d / "rep").string());
  ASSERT_EQ(r.code, 0) << r.all;
  const json rep_json = load(d / "rep" / "report.json");
  int ratio_charts = 0;
  for (const json& ch : rep_json.at("charts")) {
    const std::string id = ch.at("chart");
    EXPECT_EQ(id.find("culling/shadow"), std::string::npos) << id;
    if (ch.at("ratio_axis").is_null()) continue;
    ++ratio_charts;
    const json& ax = ch.at("ratio_axis");
    const double lo = ax.at("limits")[0], hi = ax.at("limits")[1];
    EXPECT_NEAR(lo * hi, 1.0, 1e-9) << id;  // centred on 1x on a log axis
    EXPECT_EQ(ax.at("bars_from").get<double>(), 1.0) << id;
    const std::string which = ax.at("axis");
    EXPECT_EQ(ch.at(which + "scale"), "log") << id;
    EXPECT_EQ(ch.at(which + "lim"), ax.at("limits")) << id;
    EXPECT_EQ(ch.at("label_overlaps"), 0) << id;
    if (id == "peers") {
      EXPECT_LT(lo, 0.9);         // the peer ahead shows left of 1x
      EXPECT_GT(hi, 3.2 * 1.01);  // the largest ratio and its spread
    } else if (id.find("culling") != std::string::npos) {
      EXPECT_GT(hi, 900.0 / 850.0 * 1.01) << id;  // culling's 1.06x and its spread
    } else {
      EXPECT_GT(hi, 850.0 * 1.01) << id;
    }
  }
  EXPECT_GE(ratio_charts, 3);  // accelerators (primary, shadow), culling (primary), peers
  std::ifstream in(d / "rep" / "index.html");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_NE(ss.str().find("1.01x"), std::string::npos);  // three significant digits, not "1x"
  EXPECT_EQ(ss.str().find("e+03x"), std::string::npos);
}

TEST(ReportPerf, NeitherAuditNorBenchIsRefused) {
  const fs::path d = fresh_dir("none");
  const auto r = run_rayaudit("report -o " + (d / "rep").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "rayaudit report: needs --audit FILE, --bench FILE, or both\n");
  EXPECT_FALSE(fs::exists(d / "rep"));
}

}  // namespace
