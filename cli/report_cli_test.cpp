// `rayaudit report` and `rayaudit crack-maps`: bad input is one line
// and exit 2 with nothing written; crack maps' counts match their images.
// The browser test is report_browser_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "image.h"
#include "run_rayaudit.h"

namespace {

namespace fs = std::filesystem;
using ra::test::run_rayaudit;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-report-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// A genuine audit output, small (two methods, two families).
fs::path small_audit(const fs::path& dir) {
  const fs::path a = dir / "audit.json";
  const auto r = run_rayaudit("audit --methods moller,watertight --families edge,closed-mesh --rays 600 --json " +
                              a.string());
  EXPECT_EQ(r.code, 0) << r.all;
  return a;
}

// `rayaudit report INPUTS -o DIR/rep`.
ra::test::CliResult report(const fs::path& d, const std::string& inputs) {
  return run_rayaudit("report " + inputs + " -o " + (d / "rep").string());
}

TEST(ReportCli, MissingAuditNamesTheFileExit2NothingWritten) {
  const fs::path d = fresh_dir("missing");
  const auto r = report(d, "--audit " + (d / "nope.json").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find((d / "nope.json").string() + ": no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "rep"));
  fs::remove_all(d);
}

TEST(ReportCli, MalformedJsonNamesFileAndLineExit2NothingWritten) {
  const fs::path d = fresh_dir("malformed");
  const fs::path a = small_audit(d);
  const fs::path bad = d / "bench.json";
  std::ofstream(bad) << "{\n \"context\": {},\n \"benchmarks\": [\n  {\"name\": \"kernel/x\",}\n ]\n}\n";
  const auto r = report(d, "--audit " + a.string() + " --bench " + bad.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":4: malformed JSON"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "rep"));
  fs::remove_all(d);
}

// Google Benchmark writes NaN for a counter's cv over constant values (as in
// ci/main.sh's quick run); the report reads that file as it is.
TEST(ReportCli, AcceptsGoogleBenchmarksNaN) {
  const fs::path d = fresh_dir("nan");
  const fs::path a = small_audit(d);
  const fs::path b = d / "bench.json";
  std::ofstream(b) << R"({
  "context": {"date": "2026-11-24T02:47:36+00:00", "num_cpus": 2, "library_build_type": "debug"},
  "benchmarks": [
    {"name": "kernel/moller/float/nocull/hit=50/back=0_median", "run_name": "kernel/moller/float/nocull/hit=50/back=0",
     "run_type": "aggregate", "aggregate_name": "median", "hit_rate": 5.0e-01, "ns_per_test": 3.5e+00},
    {"name": "kernel/moller/float/nocull/hit=50/back=0_cv", "run_name": "kernel/moller/float/nocull/hit=50/back=0",
     "run_type": "aggregate", "aggregate_name": "cv", "expected_hit_rate": NaN, "hit_rate": NaN,
     "ns_per_test": 7.7e-03}
  ]
})";
  const auto r = report(d, "--audit " + a.string() + " --bench " + b.string());
  ASSERT_EQ(r.code, 0) << r.all;
  const auto rep = nlohmann::json::parse(slurp(d / "rep" / "report.json"));
  bool seen = false;
  for (const auto& e : rep["speed_accuracy"])
    if (e["subject"] == "moller/float") {
      seen = true;
      EXPECT_EQ(e["ns_per_test"].get<double>(), 3.5);  // the median row, not the cv
    }
  EXPECT_TRUE(seen);
  fs::remove_all(d);
}

// A figure the page draws must be a finite number >= 0: NaN or Infinity
// outside a cv/stddev row, or a negative time, is one line and exit 2 (the
// page drew nothing, or a point off the chart, with matplotlib's warnings).
TEST(ReportCli, NonFiniteOrNegativeFiguresAreRefused) {
  const fs::path d = fresh_dir("nonfinite");
  const fs::path a = small_audit(d);
  const fs::path b = d / "bench.json";
  const std::string head = R"({"context": {"num_cpus": 2}, "benchmarks": [
    {"name": "kernel/moller/float/nocull/hit=50/back=0_median", "run_name": "kernel/moller/float/nocull/hit=50/back=0",
     "run_type": "aggregate", "aggregate_name": "median", )";
  for (const auto& [value, why] : {std::pair<std::string, std::string>{"NaN", "is NaN or infinite"},
                                   {"Infinity", "is NaN or infinite"},
                                   {"-3.0", "is negative"}}) {
    std::ofstream(b) << head << "\"ns_per_test\": " << value << "}]}";
    const auto r = report(d, "--audit " + a.string() + " --bench " + b.string());
    EXPECT_EQ(r.code, 2) << value;
    EXPECT_EQ(r.err, b.string() + ": benchmarks[0]: 'ns_per_test' " + why + (why == "is negative" ? " (-3.0)\n" : "\n"))
        << r.err;
    EXPECT_FALSE(fs::exists(d / "rep"));
  }
  fs::remove_all(d);
}

// Stage timings saved with Windows (\r\n) or classic Mac (\r) line ends
// are read as the page's Python reads them, and a bad one is still named
// by its line.
TEST(ReportCli, StagesWithAnyLineEnd) {
  const fs::path d = fresh_dir("stages");
  const fs::path a = small_audit(d);
  const fs::path st = d / "stages.tsv";
  for (const std::string eol : {"\r\n", "\r"}) {
    std::ofstream(st, std::ios::binary) << "render\t1.5" << eol << "audit\t2" << eol;
    fs::remove_all(d / "rep");
    auto r = report(d, "--audit " + a.string() + " --stages " + st.string());
    ASSERT_EQ(r.code, 0) << r.all;
    const auto rep = nlohmann::json::parse(slurp(d / "rep" / "report.json"));
    EXPECT_NE(rep.dump().find("\"audit\""), std::string::npos);
    std::ofstream(st, std::ios::binary) << "render\t1.5" << eol << "audit\tsoon" << eol;
    fs::remove_all(d / "rep");
    r = report(d, "--audit " + a.string() + " --stages " + st.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err.rfind(st.string() + ":2: ", 0), 0u) << r.err;
  }
  fs::remove_all(d);
}

TEST(ReportCli, WrongShapeNamesTheKeyExit2) {
  const fs::path d = fresh_dir("shape");
  const fs::path a = d / "audit.json";
  std::ofstream(a) << R"({"seed": 1, "rays_per_family": 10, "subjects": [{"name": "m/float"}], "cells": []})";
  fs::create_directories(d / "rep");  // an existing output directory stays untouched
  const auto r = report(d, "--audit " + a.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, a.string() + ": subjects[0]: missing 'method'\n");
  EXPECT_TRUE(fs::is_empty(d / "rep"));
  fs::remove_all(d);
}

// golden check --json (the report's golden section): one row per scene with
// the same verdict as the exit code, written on failure too.
TEST(GoldenJson, RowPerSceneWithStatusAlsoOnFailure) {
  const fs::path d = fresh_dir("golden");
  auto r = run_rayaudit("golden check doc000-pyramid --json " + (d / "g.json").string() + " --diff-dir " +
                        (d / "diffs").string());
  ASSERT_EQ(r.code, 0) << r.all;
  auto j = nlohmann::json::parse(slurp(d / "g.json"));
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scenes"][0]["name"], "doc000-pyramid");
  EXPECT_EQ(j["scenes"][0]["status"], "ok");
  // A checkout whose golden image differs: copy the repository's scene and
  // manifest, with another scene's PNG standing in for the golden.
  const fs::path root = d / "root";
  fs::create_directories(root / "golden");
  fs::copy(RAYAUDIT_SOURCE_DIR "/scenes", root / "scenes", fs::copy_options::recursive);
  fs::copy_file(RAYAUDIT_SOURCE_DIR "/golden/manifest.json", root / "golden" / "manifest.json");
  fs::copy_file(RAYAUDIT_SOURCE_DIR "/golden/doc004-cube.png", root / "golden" / "doc000-pyramid.png");
  r = run_rayaudit("golden check doc000-pyramid --root " + root.string() + " --json " + (d / "g2.json").string() +
                   " --diff-dir " + (d / "diffs").string());
  EXPECT_EQ(r.code, 1) << r.all;
  j = nlohmann::json::parse(slurp(d / "g2.json"));
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scenes"][0]["status"], "fail");
  fs::remove_all(d);
}

TEST(CrackMapsCli, BadOffsetAndOpenMeshExit2NothingWritten) {
  const fs::path d = fresh_dir("crackbad");
  auto r = run_rayaudit("crack-maps -o " + (d / "cm").string() + " --offsets 1,abc --mesh " RAYAUDIT_SOURCE_DIR
                        "/scenes/meshes/cube.obj");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "--offsets: 'abc' is not an offset between 0 and 1e30\n");
  r = run_rayaudit("crack-maps -o " + (d / "cm").string() + " --mesh " RAYAUDIT_SOURCE_DIR "/scenes/meshes/quad.obj");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("quad.obj: not a closed outward mesh"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(d / "cm"));
  fs::remove_all(d);
}

// Near the origin the watertight method finds every crossing the oracle finds
// on a closed mesh (no leak); each map's red pixels are exactly its leaks.
TEST(CrackMapsCli, NoLeakNearTheOriginAndRedPixelsAreTheLeaks) {
  const fs::path d = fresh_dir("crack");
  const auto r = run_rayaudit("crack-maps -o " + (d / "cm").string() +
                              " --size 48 --offsets 1,1e7 --methods moller,watertight --mesh " RAYAUDIT_SOURCE_DIR
                              "/scenes/meshes/tetrahedron.obj");
  ASSERT_EQ(r.code, 0) << r.all;
  const auto j = nlohmann::json::parse(slurp(d / "cm" / "crack_maps.json"));
  ASSERT_EQ(j["maps"].size(), 2u * 2u * 2u);  // sphere + tetrahedron, 2 offsets, 2 methods
  for (const auto& m : j["maps"]) {
    EXPECT_GT(m["surface_pixels"].get<long long>(), 48 * 48 / 20) << m;  // the mesh is in view
    if (m["method"] == "watertight" && m["offset"] == 1) {
      EXPECT_EQ(m["leaks"], 0) << m;
    }
    const ra::Image img = ra::read_image(d / "cm" / m["image"].get<std::string>());
    ASSERT_EQ(img.width, 48);
    long long red = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const float* p = img.at(x, y);
        red += p[0] > 0.5f && p[1] < 0.1f && p[2] < 0.1f;
      }
    EXPECT_EQ(red, m["leaks"].get<long long>()) << m;
  }
  fs::remove_all(d);
}

}  // namespace
