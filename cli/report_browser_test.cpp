// The report in a real browser: a report from a real small run
// opens in headless Chromium with every image and chart drawn, no console error.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "run_rayaudit.h"
#include "scene/scene_mesh.h"

namespace {

namespace fs = std::filesystem;
using namespace ra::test;

// Runs a command, returning its exit code and putting stdout + stderr in `out`.
int sh(const std::string& cmd, std::string& out) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  out.clear();
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128;
}

std::string chromium(const fs::path& profile) {
  return "/usr/bin/chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
         "--disable-background-networking --disable-component-update --disable-sync --user-data-dir=" +
         profile.string();
}

// A report from a real small run: the audit, crack maps, a POV-Ray comparison
// and a golden check, then opened in headless Chromium. The page checks
// itself on load (every <img> decoded, every chart's SVG with a non-empty
// box) and says so in #selfcheck; any console message fails the test. The
// screenshot is left beside the page (build dir) to look at.
TEST(ReportBrowser, RealSmallRunOpensInChromiumWithEverythingDrawn) {
  if (!fs::exists("/usr/bin/chromium")) GTEST_FAIL() << "/usr/bin/chromium missing (ci/install-deps.sh installs it)";
  const fs::path d = fs::path(RAYAUDIT_BUILD_DIR) / "report-browser-test";
  fs::remove_all(d);
  fs::create_directories(d / "pov");
  const fs::path audit = d / "audit.json";
  auto r = run_rayaudit("audit --rays 2000 --json " + audit.string());
  ASSERT_EQ(r.code, 0) << r.all;
  r = run_rayaudit("crack-maps -o " + (d / "cm").string() +
                   " --size 32 --offsets 1,1e5,1e7 --methods angles,moller,watertight --mesh " RAYAUDIT_SOURCE_DIR
                   "/scenes/meshes/tetrahedron.obj");
  ASSERT_EQ(r.code, 0) << r.all;
  const std::string scene = RAYAUDIT_SOURCE_DIR "/scenes/doc000-pyramid.json";
  r = run_rayaudit("compare " + scene + " --width 80 --height 60 --explain --json " +
                   (d / "pov/pyramid.json").string() + " --diff " + (d / "pov/pyramid-diff.png").string() + " --ours " +
                   (d / "pov/pyramid-ours.png").string() + " --pov " + (d / "pov/pyramid-pov.png").string());
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.all;  // a difference beyond tolerance is still a report
  r = run_rayaudit("golden check doc000-pyramid --json " + (d / "golden.json").string() + " --diff-dir " +
                   (d / "golden-diffs").string());
  ASSERT_TRUE(r.code == 0 || r.code == 1) << r.all;
  std::ofstream(d / "stages.tsv") << "audit\t1\ncrack maps\t2\n";
  const std::string inputs = "report --audit " + audit.string() + " --compare " + (d / "pov").string() +
                             " --crack-maps " + (d / "cm").string() + " --golden " + (d / "golden.json").string() +
                             " --stages " + (d / "stages.tsv").string();
  // Without a benchmark the speed sections say so plainly.
  r = run_rayaudit(inputs + " -o " + (d / "report-nobench").string());
  ASSERT_EQ(r.code, 0) << r.all;
  EXPECT_NE(slurp(d / "report-nobench" / "index.html").find("No benchmark given"), std::string::npos);
  // A real benchmark, a small subset: the kernels of two methods at 50% hits,
  // the box rung under each accelerator, one peer.
  const bool corpus = fs::exists(ra::cache_dir() / "corpus" / "ladder" / "box.obj");
  std::string bench_arg;
  if (corpus) {
    r = run_rayaudit(
        "bench --quick --benchmark_repetitions=1 --json " + (d / "bench.json").string() +
        " --filter '^(kernel/(moller|watertight)/(float|double)/nocull/hit=50/back=0"
        "|scene/box/(none|sphere|bvh)/(cull|nocull)/primary/threads=1|peer/tinyobjloader/bunny_glmark2)$'");
    ASSERT_EQ(r.code, 0) << r.all;
    bench_arg = " --bench " + (d / "bench.json").string();
  }
  r = run_rayaudit(inputs + bench_arg + " -o " + (d / "report").string());
  ASSERT_EQ(r.code, 0) << r.all;
  const fs::path page = d / "report" / "index.html";
  ASSERT_TRUE(fs::exists(page));
  EXPECT_LT(fs::file_size(page), 4u << 20);  // a few MB at most
  const std::string html = slurp(page);
  // Nothing fetched, so it opens offline (SVG namespaces are names, not fetches).
  for (const char* ref : {"src=\"http", "href=\"http", "url(http", "@import", "<link"})
    EXPECT_EQ(html.find(ref), std::string::npos) << ref;
  EXPECT_EQ(html.find("No benchmark given") == std::string::npos, corpus);

  const auto rep = nlohmann::json::parse(slurp(d / "report" / "report.json"));
  for (const char* k : {"speed_accuracy", "stability", "crack_maps", "optimisations", "peers", "images", "machine"})
    EXPECT_TRUE(rep.contains(k)) << k;
  EXPECT_EQ(rep["crack_maps"].size(), 2u * 3u * 3u);
  EXPECT_EQ(rep["images"].size(), 1u);
  for (const auto& e : rep["speed_accuracy"]) {
    for (const char* k : {"subject", "ns_per_test", "wrong_pct", "leaks_per_million"}) EXPECT_TRUE(e.contains(k)) << k;
    // The benchmark's kernel rows are on the speed axis.
    if (corpus && (e["subject"] == "moller/float" || e["subject"] == "watertight/double")) {
      EXPECT_GT(e["ns_per_test"].get<double>(), 0) << e;
    }
  }
  if (corpus) {
    EXPECT_FALSE(rep["optimisations"]["speedups"].empty());
    EXPECT_FALSE(rep["peers"].empty());
  }

  // Expected on the page: each crack map and the three thumbnails of the scene.
  const int images = 2 * 3 * 3 + 3;
  std::string dom;
  const fs::path profile = d / "chromium-profile";
  int rc = sh(chromium(profile) + " --enable-logging=stderr --v=0 --virtual-time-budget=10000 --dump-dom file://" +
                  page.string(),
              dom);
  ASSERT_EQ(rc, 0) << dom;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex(R"(<p id="selfcheck"[^>]*>)"))) << dom.substr(0, 2000);
  const std::string tag = m.str();
  EXPECT_NE(tag.find("data-result=\"ok\""), std::string::npos) << tag;
  EXPECT_NE(tag.find("data-images=\"" + std::to_string(images) + "\""), std::string::npos) << tag;
  std::smatch charts;
  ASSERT_TRUE(std::regex_search(tag, charts, std::regex(R"re(data-charts="(\d+)")re")));
  // Speed/accuracy (or correctness alone), a dozen stability charts, crack
  // leaks, and with a benchmark the speed-ups, the slope and the peers.
  EXPECT_GE(std::stoi(charts[1]), corpus ? 19 : 16);
  // Chromium logs every console message as ":CONSOLE(line)"; the page writes none.
  // (Found with find, not std::regex: libstdc++'s regex recurses once a
  // character and overflowed the stack on the multi-megabyte DOM under ASan.)
  const std::size_t console = dom.find("CONSOLE");
  if (console != std::string::npos) {
    const std::size_t from = dom.rfind('\n', console), to = dom.find('\n', console);
    ADD_FAILURE() << dom.substr(from == std::string::npos ? 0 : from + 1,
                                to == std::string::npos ? std::string::npos : to - from);
  }
  EXPECT_EQ(dom.find("Uncaught"), std::string::npos);

  const fs::path shot = d / "report" / "screenshot.png";
  std::string log;
  rc = sh("cd " + d.string() + " && " + chromium(profile) +
              " --hide-scrollbars --window-size=1280,2400 --screenshot=" + shot.string() + " file://" + page.string(),
          log);
  ASSERT_EQ(rc, 0) << log;
  ASSERT_TRUE(fs::exists(shot)) << log;
  EXPECT_GT(fs::file_size(shot), 20000u);  // a page of charts, not a blank
}

}  // namespace
