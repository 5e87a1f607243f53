// `rayaudit report` and `rayaudit crack-maps`: bad input is one line
// and exit 2 with nothing written (what the page cannot draw, a byte-order
// mark, an unreadable image, an output that is an input, absurd work);
// crack maps' counts match their images.
// The browser test is report_browser_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "image.h"
#include "run_rayaudit.h"

namespace {

namespace fs = std::filesystem;
using namespace ra::test;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-report-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// A genuine audit output, small (two methods, two families).
fs::path small_audit(const fs::path& dir) {
  const fs::path a = dir / "audit.json";
  const auto r =
      run_rayaudit("audit --methods moller,watertight --families edge,closed-mesh --rays 600 --json " + a.string());
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

// The stability section's refracted rays: a chart and a table with a row
// per kind, precision and strategy, whose spawned counts are the audit's.
TEST(ReportCli, StabilityShowsRefractedRaysPerStrategyAndScale) {
  const fs::path d = fresh_dir("refracted");
  const fs::path a = d / "audit.json";
  ASSERT_EQ(run_rayaudit("audit --methods moller,kraus --families refracted --rays 160 --json " + a.string()).code, 0);
  const auto r = report(d, "--audit " + a.string());
  ASSERT_EQ(r.code, 0) << r.all;
  const std::string html = slurp(d / "rep" / "index.html");
  EXPECT_NE(html.find("<h3>refracted</h3>"), std::string::npos);
  EXPECT_NE(html.find("self-hit % / skipped %"), std::string::npos);
  const auto rep = nlohmann::json::parse(slurp(d / "rep" / "report.json"));
  ASSERT_EQ(rep["refracted"].size(), 2u * 2u * 4u);  // kinds x precisions x strategies
  std::uint64_t in_report = 0, in_audit = 0;
  for (const auto& row : rep["refracted"]) {
    EXPECT_EQ(row["scales"].size(), 4u) << row.dump();
    for (const auto& e : row["scales"]) in_report += e["spawned"].get<std::uint64_t>();
  }
  const auto audit = nlohmann::json::parse(slurp(a));
  for (const auto& c : audit["cells"]) in_audit += c["stats"]["spawned"].get<std::uint64_t>();
  EXPECT_GT(in_audit, 0u);
  EXPECT_EQ(in_report, in_audit);
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
  auto r = run_rayaudit("crack-maps -o " + (d / "cm").string() +
                        " --offsets 1,abc --mesh " RAYAUDIT_SOURCE_DIR "/scenes/meshes/cube.obj");
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

// The exact method answers as the oracle on every pixel of every map: no
// leak, no false pixel, at every default offset, at the default size
// (where the watertight method has false pixels on the sphere at 1e5: they
// are no crossing, so nobody's leak).
TEST(CrackMapsCli, ExactHasNoLeakAndNoFalsePixelAtAnyOffset) {
  const fs::path d = fresh_dir("crack-exact");
  const auto r =
      run_rayaudit("crack-maps -o " + (d / "cm").string() +
                   " --methods exact,watertight --mesh " RAYAUDIT_SOURCE_DIR "/scenes/meshes/tetrahedron.obj");
  ASSERT_EQ(r.code, 0) << r.all;
  const auto j = nlohmann::json::parse(slurp(d / "cm" / "crack_maps.json"));
  ASSERT_EQ(j["maps"].size(), 2u * 4u * 2u);  // sphere + tetrahedron, 4 offsets, 2 methods
  long long watertight_wrong = 0;
  for (const auto& m : j["maps"]) {
    EXPECT_GT(m["surface_pixels"].get<long long>(), 96 * 96 / 20) << m;  // the mesh is in view
    if (m["method"] == "exact") {
      EXPECT_EQ(m["leaks"], 0) << m;
      EXPECT_EQ(m["false_hits"], 0) << m;
    } else {
      watertight_wrong += m["leaks"].get<long long>() + m["false_hits"].get<long long>();
    }
  }
  EXPECT_GT(watertight_wrong, 0);  // the maps are hard enough to tell
  fs::remove_all(d);
}

// crack-maps names every map before the work: a --mesh named like the
// built-in sphere would share its maps' names (one of each pair lost), and a
// name longer than the file system takes failed after the work, leaving a
// partial directory. Both are refused first, and no directory is left.
TEST(CrackMapsCli, CrackMapsRefusesCollidingAndOverlongNamesBeforeTheWork) {
  const fs::path d = scratch_dir("crack-names");
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  std::ofstream(d / "sphere.obj") << tetra;
  const std::string long_stem(248, 'm');
  std::ofstream(d / (long_stem + ".obj")) << tetra;
  const std::string cm = (d / "cm").string();
  const auto a = run_rayaudit("crack-maps -o " + cm + " --methods moller --offsets 1 --size 8 --mesh " +
                              (d / "sphere.obj").string());
  EXPECT_EQ(a.code, 2) << a.all;
  EXPECT_TRUE(one_line(a.err)) << a.err;
  EXPECT_NE(a.err.find("sphere-moller-1.png: two maps would have this name"), std::string::npos) << a.err;
  const auto b = run_rayaudit("crack-maps -o " + cm + " --methods moller --offsets 1 --size 8 --mesh " +
                              (d / (long_stem + ".obj")).string());
  EXPECT_EQ(b.code, 2) << b.all;
  EXPECT_TRUE(one_line(b.err)) << b.err;
  EXPECT_NE(b.err.find("file name too long"), std::string::npos) << b.err;
  EXPECT_FALSE(fs::exists(cm)) << "left behind";
}

// report: its audit input named as its report.json output is refused before
// the script runs; stage times of nan, -5 or with a NUL are refused at their
// line (they were drawn, or failed as a Python traceback).
TEST(ReportCli, ReportRefusesItsInputAsOutputAndBadStageTimes) {
  const fs::path d = scratch("report-in-out");
  fs::remove_all(d);
  fs::create_directories(d / "rep");
  const fs::path audit = d / "rep" / "report.json";
  ASSERT_EQ(run_rayaudit("audit --rays 50 --families edge --methods moller --json " + audit.string()).code, 0);
  const std::string before = slurp(audit);
  auto r = run_rayaudit("report --audit " + audit.string() + " -o " + (d / "rep").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, audit.string() + ": is also an input of this command (" + audit.string() +
                       "): it would be replaced; choose another output\n");
  EXPECT_EQ(slurp(audit), before);
  EXPECT_FALSE(fs::exists(d / "rep" / "index.html"));
  for (const std::string& stage :
       {std::string("build\tnan\n"), std::string("build\t-5\n"), std::string("build\t1\0x\n", 10)}) {
    std::ofstream(d / "st.tsv", std::ios::binary) << stage;
    r = run_rayaudit("report --audit " + audit.string() + " --stages " + (d / "st.tsv").string() + " -o " +
                     (d / "out").string());
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind((d / "st.tsv").string() + ":1: ", 0), 0u) << r.err;
  }
  EXPECT_FALSE(fs::exists(d / "out"));
}

// An OBJ read through its memory map was not noted as an
// input, so `crack-maps --mesh` naming one of its own maps overwrote it.
TEST(CrackMapsCli, CrackMapsMeshThatIsOneOfItsMapsIsRefused) {
  const fs::path dir = scratch_dir("cm-mesh-input");
  const fs::path mesh = dir / "sphere-moller-1.png";
  fs::copy_file(kScenes + "/meshes/tetrahedron.obj", mesh);
  const std::string before = slurp(mesh);
  const auto r = run_rayaudit("crack-maps -o " + dir.string() + " --mesh " + mesh.string() +
                              " --methods moller --offsets 1 --size 8");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("sphere-moller-1.png: is also an input of this command"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(mesh), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

// An audit JSON with a UTF-8 BOM passed the C++ checks and
// ended in a 13-line Python traceback; report.py reads it as utf-8-sig.
TEST(ReportCli, ReportReadsAnAuditJsonWithABom) {
  const fs::path dir = scratch_dir("report-bom");
  const fs::path audit = dir / "a.json";
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 20 --json " + audit.string()).code, 0);
  std::ofstream(dir / "bom.json") << "\xEF\xBB\xBF" << slurp(audit);
  const auto r = run_rayaudit("report --audit " + (dir / "bom.json").string() + " -o " + (dir / "rep").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(dir / "rep" / "index.html"));
  fs::remove_all(dir);
}

// An image beside a compare JSON that PIL cannot open ended
// the report in a 13-line traceback; it is one line naming the image.
TEST(ReportCli, ReportWithAnUnreadableCompareImageIsOneLine) {
  const fs::path dir = scratch("report-f40");
  fs::remove_all(dir);
  fs::create_directories(dir / "cmp");
  const fs::path audit = dir / "a.json";
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 20 --json " + audit.string()).code, 0);
  std::ofstream(dir / "cmp" / "x.json")
      << R"({"width": 8, "height": 8, "differing": 0, "identical": true, "differences": []})";
  std::ofstream(dir / "cmp" / "x-pov.png") << "not a png\n";
  const auto r = run_rayaudit("report --audit " + audit.string() + " --compare " + (dir / "cmp").string() + " -o " +
                              (dir / "rep").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind((dir / "cmp" / "x-pov.png").string() + ": not a readable image (", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir / "rep"));
  fs::remove_all(dir);
}

// A --mesh whose path is one of the maps was overwritten by that map.
TEST(CrackMapsCli, CrackMapsMeshThatIsAnOutputIsRefused) {
  const fs::path dir = scratch("cm-identity");
  fs::create_directories(dir);
  const fs::path mesh = dir / "sphere-moller-1.png";
  fs::copy_file(kScenes + "/meshes/tetrahedron.obj", mesh, fs::copy_options::overwrite_existing);
  const std::string before = slurp(mesh);
  const auto r = run_rayaudit("crack-maps -o " + dir.string() + " --mesh " + mesh.string() +
                              " --methods moller --offsets 1 --size 8");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find(mesh.string() + ": is also an input of this command"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(mesh), before);
  EXPECT_FALSE(fs::exists(dir / "crack_maps.json"));
}

// The flags' own limits multiplied to ~34 hours, run silently.
TEST(CrackMapsCli, CrackMapsAbsurdWorkIsRefusedWithItsSize) {
  const fs::path dir = scratch("cm-absurd");
  const auto r = run_rayaudit("crack-maps -o " + dir.string() + " --mesh " + kScenes +
                              "/meshes/tetrahedron.obj --size 1024 --offsets 1,10,100,1000,1e4");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err,
            "crack-maps: 90 maps of 1024x1024 pixels are 94371840 pixels (about 117 core-minutes); the "
            "limit is 16777216: fewer --offsets or --methods, or a smaller --size\n");
  EXPECT_FALSE(fs::exists(dir));
}

// Inputs the C++ checks let through ended in Python tracebacks.
TEST(ReportCli, ReportRefusesWhatThePageCannotDrawInOneLine) {
  const fs::path audit = scratch("rep-audit.json");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 50 --json " + audit.string()).code, 0);
  const std::string text = slurp(audit);
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    return scratch_variant(text, name, from, to);
  };
  struct Case {
    fs::path file;
    std::string extra, message;
  };
  const fs::path stages = scratch("hex.tsv");
  std::ofstream(stages) << "a\t0x10\n";
  const std::vector<Case> cases = {
      {variant("rep-subject.json", "\"subject\": \"moller/float\"", "\"subject\": \"moller\""), "",
       ": cells[0]: subject 'moller' is not METHOD/PRECISION"},
      {variant("rep-negative.json", "\"tests\": ", "\"tests\": -5, \"was\": "), "", " is negative"},
      {audit, " --stages " + stages.string(), "hex.tsv:1: seconds '0x10' is not a decimal number"},
  };
  for (const auto& c : cases) {
    const fs::path out = scratch("rep-out");
    const auto r = run_rayaudit("report --audit " + c.file.string() + c.extra + " -o " + out.string());
    EXPECT_EQ(r.code, 2) << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// A UTF-8 byte-order mark before the audit JSON (the C++ check took it,
// the script's json.load did not).
TEST(ReportCli, ReportReadsAnAuditJsonWithAByteOrderMark) {
  const fs::path audit = scratch("bom-audit.json"), out = scratch("bom-report");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 50 --json " + audit.string()).code, 0);
  const std::string text = slurp(audit);
  std::ofstream(audit, std::ios::binary) << "\xef\xbb\xbf" << text;
  const auto r = run_rayaudit("report --audit " + audit.string() + " -o " + out.string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(out / "index.html"));
  fs::remove_all(out);
}

// A corrupt or huge image beside a compare JSON ended in a PIL
// traceback; now one line naming the image, exit 2, nothing written.
TEST(ReportCli, ReportNamesAnUnreadableOrHugeImageInOneLine) {
  const fs::path audit = scratch("img-audit.json"), dir = scratch("img-cmp");
  ASSERT_EQ(run_rayaudit("audit --methods moller --families edge --rays 50 --json " + audit.string()).code, 0);
  fs::create_directories(dir);
  std::ofstream(dir / "x.json") << R"({"width": 8, "height": 8, "differing": 0, "identical": true, "differences": []})";
  std::ofstream(dir / "x-pov.png") << "not a png\n";
  const fs::path out = scratch("img-report");
  auto r = run_rayaudit("report --audit " + audit.string() + " --compare " + dir.string() + " -o " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("x-pov.png: not a readable image"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // A PNG header declaring 16384 x 16384 (what compare --width 16384 writes):
  // refused from its size, not decoded (PIL's bomb error was 15 lines).
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x40\0\0\0\x40\0\x08\x02\0\0\0", 29);
  png += "\x26\xaa\x87\xd3";                               // the IHDR chunk's CRC (PIL checks it on opening)
  png += std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12);  // PIL reads the next chunk's header too
  std::ofstream(dir / "x-pov.png", std::ios::binary) << png;
  r = run_rayaudit("report --audit " + audit.string() + " --compare " + dir.string() + " -o " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("x-pov.png: 16384x16384 is too large to show in the report"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
