// `rayaudit bench` run as a user would: the JSON of a small
// --quick subset holds every group with the names and counters users'
// scripts read (bench/README.md), and bad input is one line, exit 2, nothing written. No timings are
// asserted (those belong in the benchmark's output).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "io/full_disk.h"
#include "run_rayaudit.h"
#include "scene/scene_mesh.h"

namespace {

namespace fs = std::filesystem;
using ra::test::run_rayaudit;

fs::path temp_json(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-bench-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / name;
  fs::remove(p);
  return p;
}

bool corpus_present() { return fs::exists(ra::cache_dir() / "corpus" / "ladder" / "bunny_glmark2.obj"); }

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// One row of every group (kernel, scene, peer, obj, oracle); one repetition (the flag passes
// through to Google Benchmark).
const char* const kSubset =
    "^(kernel/(moller|watertight)/float/(cull|nocull)/hit=50/back=(0|100)"
    "|kernel/stable/double/nocull/hit=50/back=0|kernel/plane/double/nocull/hit=50/back=0"
    "|scene/box/(none|sphere|bvh)/(cull|nocull)/(primary|shadow)/threads=1"
    "|peer/embree/bunny/(primary|shadow|build)/default/threads=1"
    "|peer/cgal/bunny/(primary|shadow)/threads=1|peer/tinyobjloader/bunny_glmark2|peer/pov/bunny/threads=1"
    "|oracle/random/threads=1|obj/bunny_glmark2/serial)$";

TEST(BenchCli, QuickSubsetHasEveryGroupNamesAndCounters) {
  if (!corpus_present()) GTEST_SKIP() << "mesh corpus not fetched (ci/fetch-corpus.sh)";
  const fs::path out = temp_json("subset.json");
  const auto r = run_rayaudit(std::string("bench --quick --benchmark_repetitions=1 --json ") + out.string() +
                              " --filter '" + kSubset + "'");
  ASSERT_EQ(r.code, 0) << r.all;
  ASSERT_TRUE(fs::exists(out));
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("context"));  // Google Benchmark's format (compare.py reads it)
  // One repetition was asked for, but a repetition beside a slow
  // calibration is run again: such a row has two repetitions and then
  // Google Benchmark's aggregate rows (NAME_mean, ...), which compare.py reads.
  std::map<std::string, nlohmann::json> rows;
  std::vector<nlohmann::json> aggregates;
  for (const auto& b : j.at("benchmarks")) {
    EXPECT_FALSE(b.value("error_occurred", false)) << b.dump();
    if (b.value("run_type", "") == "aggregate")
      aggregates.push_back(b);
    else
      rows[b.at("name").get<std::string>()] = b;
  }
  for (const auto& a : aggregates) {
    const std::string run = a.at("run_name").get<std::string>(), agg = a.at("aggregate_name").get<std::string>();
    EXPECT_TRUE(rows.count(run)) << "an aggregate of no row: " << a.dump();
    EXPECT_EQ(a.at("name").get<std::string>(), run + "_" + agg);
    EXPECT_TRUE(std::set<std::string>({"mean", "median", "stddev", "cv"}).count(agg)) << agg;
    EXPECT_GE(a.at("repetitions").get<int>(), 2) << a.dump();
  }
  const std::regex kernel("^kernel/[a-z0-9_-]+/(float|double)/(cull|nocull)/hit=(0|10|50|90|100)/back=(0|50|100)$");
  const std::regex scene("^scene/[a-z-]+/(none|sphere|bvh)/(cull|nocull)/(primary|shadow)/threads=[0-9]+$");
  const std::regex peer("^peer/(embree|pov|tinyobjloader|cgal)/.+$");
  const std::regex oracle("^oracle/[a-z-]+/threads=[0-9]+$");
  const std::regex obj("^obj/[A-Za-z0-9_-]+/(serial|parallel)$");
  std::map<std::string, int> groups;
  for (const auto& row : rows) {
    const std::string& name = row.first;  // not a structured binding: clang 14 cannot capture those
    const std::string group = name.substr(0, name.find('/'));
    ++groups[group];
    const auto& c = row.second;
    auto has = [&](const char* counter) { EXPECT_TRUE(c.contains(counter)) << name << " lacks " << counter; };
    if (group == "kernel") {
      EXPECT_TRUE(std::regex_match(name, kernel)) << name;
      has("ns_per_test");
    } else if (group == "scene") {
      EXPECT_TRUE(std::regex_match(name, scene)) << name;
      for (const char* k : {"Mrays_per_s", "triangles", "hits", "build_s", "bytes_per_triangle"}) has(k);
    } else if (group == "peer") {
      EXPECT_TRUE(std::regex_match(name, peer)) << name;
      ASSERT_TRUE(c.contains("ratio")) << name;
      EXPECT_GT(c.at("ratio").get<double>(), 0) << name;
    } else if (group == "oracle") {
      EXPECT_TRUE(std::regex_match(name, oracle)) << name;
      has("cases/s");
    } else if (group == "obj") {
      EXPECT_TRUE(std::regex_match(name, obj)) << name;
    } else {
      ADD_FAILURE() << "row outside the five groups: " << name;
    }
  }
  for (const char* g : {"kernel", "scene", "peer", "oracle", "obj"}) EXPECT_GT(groups[g], 0) << g;
  // Exactly the rows asked for: 8 + 2 kernel, 3 accels x 2 culls x 2 ray kinds (the box is closed).
  EXPECT_EQ(groups["kernel"], 10);
  EXPECT_EQ(groups["scene"], 12);
  for (const char* p :
       {"peer/embree/bunny/primary/default/threads=1", "peer/embree/bunny/shadow/default/threads=1",
        "peer/embree/bunny/build/default/threads=1", "peer/cgal/bunny/primary/threads=1",
        "peer/cgal/bunny/shadow/threads=1", "peer/tinyobjloader/bunny_glmark2", "peer/pov/bunny/threads=1"})
    EXPECT_TRUE(rows.count(p)) << p;

  // Culling changes the answer where rays meet back faces, not elsewhere.
  auto counter = [&](const std::string& name, const char* k) { return rows.at(name).at(k).get<double>(); };
  EXPECT_EQ(counter("kernel/moller/float/nocull/hit=50/back=100", "hit_rate"), 0.5);
  EXPECT_EQ(counter("kernel/moller/float/cull/hit=50/back=100", "hit_rate"), 0.0);
  EXPECT_EQ(counter("kernel/moller/float/cull/hit=50/back=0", "hit_rate"), 0.5);
  // On the closed box, culling and the bounding sphere never change what a ray hits.
  for (const char* kind : {"primary", "shadow"}) {
    const std::string tail = std::string("/") + kind + "/threads=1";
    const double none = counter("scene/box/none/nocull" + tail, "hits");
    for (const char* v : {"none/cull", "sphere/nocull", "sphere/cull"})
      EXPECT_EQ(counter(std::string("scene/box/") + v + tail, "hits"), none) << v << tail;
  }
  EXPECT_GT(counter("scene/box/none/nocull/primary/threads=1", "hits"), 0);
  EXPECT_EQ(counter("scene/box/bvh/nocull/primary/threads=1", "triangles"), 12);
  // The BVH's leaf blocks hold what the loop keeps per triangle, and its
  // nodes come on top: its bytes per triangle exceed the loop's. (Its nodes
  // and blocks are over-aligned; when the count missed aligned allocations
  // the BVH showed 139 bytes a triangle against the loop's 202.)
  EXPECT_GT(counter("scene/box/bvh/nocull/primary/threads=1", "bytes_per_triangle"),
            counter("scene/box/none/nocull/primary/threads=1", "bytes_per_triangle"));

  // Embree and ours agree on which rays hit, except rays within rounding of
  // an edge (Embree's float vertices against our doubles): at most 1 in 10,000.
  for (const char* p : {"peer/embree/bunny/primary/default/threads=1", "peer/embree/bunny/shadow/default/threads=1",
                        "peer/cgal/bunny/primary/threads=1", "peer/cgal/bunny/shadow/threads=1"}) {
    const double rays = counter(p, "rays"), differ = counter(p, "differ");
    EXPECT_GT(counter(p, "hits"), 0) << p;
    EXPECT_LE(differ, std::max(1.0, rays / 10000)) << p;
    EXPECT_LE(std::abs(counter(p, "hits") - counter(p, "ours_hits")), differ) << p;
  }
  for (const char* k : {"pov_parse_s", "pov_trace_s", "pov_process_s", "ours_trace_s"})
    EXPECT_GT(counter("peer/pov/bunny/threads=1", k), 0) << k;
  EXPECT_NE(r.out.find("rays differ"), std::string::npos) << "the hit-count agreement is printed";
}

// Bad input: one line on stderr, exit 2, the --json file not written.
void expect_refused(const std::string& args, const std::string& message, const std::string& env = "") {
  const fs::path out = temp_json("refused.json");
  const auto r = run_rayaudit("bench --quick --json " + out.string() + " " + args, env);
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  // No temporary left beside it either.
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(BenchCli, UnknownFilterGroupIsRefused) {
  expect_refused("--filter 'kernal/moller'", "unknown group \"kernal\"");
  expect_refused("--filter nothing-matches-this", "selects no benchmark");
  expect_refused("--filter '('", "not a regular expression");
}

TEST(BenchCli, UnwritableJsonIsRefused) {
  const auto r =
      run_rayaudit("bench --quick --json /nonexistent-dir/b.json --filter kernel/moller/float/cull/hit=0/back=0");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("/nonexistent-dir/b.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists("/nonexistent-dir/b.json"));
}

TEST(BenchCli, MissingCorpusFileIsNamed) {
  const fs::path empty = fs::temp_directory_path() / ("rayaudit-bench-empty-cache-" + std::to_string(::getpid()));
  fs::create_directories(empty);
  expect_refused("--filter scene/box/",
                 (empty / "corpus/ladder/box.obj").string() +
                     ": missing from the mesh corpus: "
                     "ci/fetch-corpus.sh fetches it",
                 "RAYAUDIT_CACHE=" + empty.string());
  fs::remove_all(empty);
}

// Killed mid-run (timeout sends SIGTERM after 4 s of a ~30 s run): neither
// the JSON nor its temporary is left behind.
TEST(BenchCli, InterruptedRunWritesNothing) {
  const fs::path out = temp_json("interrupted.json");
  const auto r = run_rayaudit("bench --quick --json " + out.string() + " --filter kernel/", "timeout -s TERM 4");
  EXPECT_EQ(r.code, 124) << r.all;  // timeout's code: the run was still going
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

// --runs keeps each run's JSON in a temporary directory ($TMPDIR): an
// interrupted run removes it, dies of the signal and writes nothing.
TEST(BenchCli, InterruptedRunsRemoveTheirTemporaryDirectory) {
  const fs::path out = temp_json("interrupted-runs.json");
  const fs::path tmp = out.parent_path() / "tmpdir";
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  const auto r = run_rayaudit("bench --quick --runs 2 --json " + out.string() + " --filter kernel/",
                              "TMPDIR=" + tmp.string() + " timeout -s TERM 4");
  EXPECT_EQ(r.code, 124) << r.all;  // timeout's code: the run was still going
  EXPECT_NE(r.err.find("interrupted in run 1 of 2; nothing written"), std::string::npos) << r.all;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(tmp)) ADD_FAILURE() << "left behind: " << e.path();
}

// A peer that is not installed is an error before anything runs, not a skip.
TEST(BenchCli, MissingPovRayIsAnError) {
  if (!corpus_present()) GTEST_SKIP() << "mesh corpus not fetched (ci/fetch-corpus.sh)";
  expect_refused("--filter peer/pov/", "RAYAUDIT_POVRAY=/nonexistent/povray is not an executable program",
                 "RAYAUDIT_POVRAY=/nonexistent/povray");
}

// The table redirected to a file (a CI log) holds no colour escapes, even
// where TERM names a colour terminal: our reporter is passed to Google
// Benchmark, and a ConsoleReporter made by hand colours unless told not to.
// --benchmark_color=true still asks for them.
TEST(BenchCli, NoColourEscapesUnlessOnATerminalOrAsked) {
  const std::string row =
      "--filter '^kernel/plane/double/nocull/hit=50/back=0$' --benchmark_repetitions=1 "
      "--benchmark_min_time=0.01";
  auto r = run_rayaudit("bench " + row, "TERM=xterm-256color");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("kernel/plane/double"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
  r = run_rayaudit("bench " + row + " --benchmark_color=true", "TERM=xterm-256color");
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find('\x1b'), std::string::npos) << r.out;
}

TEST(BenchCli, OtherArgumentsAreRefused) {
  expect_refused("--bogus", "unknown argument \"--bogus\"");
  expect_refused("--benchmark_out=x.json", "use --json OUT");
  expect_refused("--threads 0", "--threads");
}

// Google Benchmark flags with bad values: one line naming the flag, exit 2,
// before anything runs (a negative count was "vector::reserve"
// exit 1, an unknown format printed the usage text with exit 0).
TEST(BenchCli, BadBenchmarkFlagValuesAreRefused) {
  expect_refused("--benchmark_repetitions=-5", "--benchmark_repetitions: \"-5\" is not a whole number");
  expect_refused("--benchmark_repetitions=abc", "--benchmark_repetitions: \"abc\"");
  expect_refused("--benchmark_repetitions=100000000", "from 1 to 1000");
  expect_refused("--benchmark_format=xml", "--benchmark_format: \"xml\" is not supported");
  expect_refused("--benchmark_min_time=0x10", "--benchmark_min_time");
  expect_refused("--benchmark_list_tests=maybe", "--benchmark_list_tests: \"maybe\" is not true or false");
  expect_refused("--benchmark_bogus=1", "--benchmark_bogus: \"1\" is not a Google Benchmark flag");
}

// Listing runs nothing: with --json the old file stayed 0 bytes;
// now refused and the old file untouched. Without --json it lists.
TEST(BenchCli, ListTestsNeverTouchesTheJson) {
  const fs::path out = temp_json("listed.json");
  std::ofstream(out) << "PRECIOUS\n";
  const auto r = run_rayaudit("bench --benchmark_list_tests=true --json " + out.string() +
                              " --filter kernel/moller/float/nocull/hit=50/back=0");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--benchmark_list_tests"), std::string::npos) << r.err;
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "PRECIOUS\n");
  const auto l = run_rayaudit("bench --benchmark_list_tests --filter kernel/moller/float/nocull/hit=50/back=0");
  EXPECT_EQ(l.code, 0) << l.all;
  EXPECT_NE(l.out.find("kernel/moller/float/nocull/hit=50/back=0"), std::string::npos) << l.out;
}

// --json naming a corpus mesh the run reads (it was replaced).
TEST(BenchCli, JsonThatIsACorpusInputIsRefused) {
  const fs::path cache = fs::temp_directory_path() / ("rayaudit-bench-cache-" + std::to_string(::getpid()));
  fs::create_directories(cache / "corpus" / "ladder");
  const fs::path mesh = cache / "corpus" / "ladder" / "box.obj";
  const std::string box = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(mesh) << box;
  const auto r = run_rayaudit("bench --filter scene/box/none/nocull/primary/threads=1 --json " + mesh.string(),
                              "RAYAUDIT_CACHE=" + cache.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("is also an input of this command"), std::string::npos) << r.err;
  std::ifstream in(mesh);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, box);
  fs::remove_all(cache);
}

// A full disk: exit 2 with one line, the old JSON kept (exit
// 0 and a truncated JSON in its place). Google Benchmark's JSON is held in
// memory and written with every write checked.
TEST(BenchCli, FullDiskKeepsTheOldJson) {
  ra::test::FullDisk disk(2048);
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "b.json";
  std::ofstream(out) << "PRECIOUS\n";
  const auto r = run_rayaudit("bench --benchmark_repetitions=1 --benchmark_min_time=0.001 --json " + out.string() +
                              " --filter 'kernel/(moller|watertight)/(float|double)/'");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(out.string() + ": cannot write"), std::string::npos) << r.err;
  std::ifstream in(out);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "PRECIOUS\n");
}

}  // namespace

// On a full disk Google Benchmark's writer cut the JSON short
// and it replaced the previous file, exit 0. Root only (a 64 KiB tmpfs).
TEST(BenchCli, FullDiskKeepsThePreviousJson) {
  ra::test::FullDisk disk(1024);
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path out = disk.dir() / "b.json";
  std::ofstream(out) << "PRECIOUS\n";
  const auto r =
      run_rayaudit("bench --filter 'kernel/moller/(float|double)/' --benchmark_repetitions=1 --json " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find(out.string() + ": cannot write: "), std::string::npos) << r.err;
  std::ifstream in(out);
  std::string kept;
  std::getline(in, kept);
  EXPECT_EQ(kept, "PRECIOUS");
}
