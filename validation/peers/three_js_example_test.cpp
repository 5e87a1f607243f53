// examples/grade/three_intersect_triangle.mjs as a user runs it: cases
// exported with decimal numbers, answered by three.js's own
// Ray.intersectTriangle under node (three from the corpus cache, fetched by
// ci/fetch-corpus.sh), graded with --grade. Fails when its figures regress.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path three_dir() {
  const char* c = std::getenv("RAYAUDIT_CACHE");
  const fs::path cache = c && *c ? fs::path(c) : fs::path(std::getenv("HOME")) / ".cache/rayaudit";
  return cache / "corpus/npm/three";
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-three-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

}  // namespace

TEST(ThreeJsExample, GradesRayIntersectTriangleThroughNode) {
  const fs::path three = three_dir();
  if (!fs::exists(three / ".done")) {
    // CI fetches the corpus into an empty cache before ctest (ci/test.sh):
    // there, a missing three is a broken fetch step, not a reason to skip.
    if (std::getenv("CI")) FAIL() << "CI: ci/fetch-corpus.sh did not fetch three.js into " << three;
    GTEST_SKIP() << "three.js is not in the cache (" << three << "): run ci/fetch-corpus.sh";
  }
  const fs::path cases = scratch("cases.csv"), answers = scratch("three.csv"), json = scratch("graded.json");
  const auto ex = run_rayaudit("audit --export-cases " + cases.string() +
                               " --numbers decimal --families edge,vertex,closed-mesh --rays 20000");
  ASSERT_EQ(ex.code, 0) << ex.all;
  const std::string text = slurp(cases);
  ASSERT_EQ(text.find("0x"), std::string::npos) << "decimal numbers only: JavaScript reads no hex floats";
  const std::string script = std::string(RAYAUDIT_SOURCE_DIR) + "/examples/grade/three_intersect_triangle.mjs";
  const std::string cmd =
      "node '" + script + "' '" + three.string() + "' '" + cases.string() + "' '" + answers.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (node: Debian's nodejs, ci/install-deps.sh)";
  const auto g =
      run_rayaudit("audit --grade " + answers.string() + " --cases " + cases.string() + " --json " + json.string());
  ASSERT_EQ(g.code, 0) << g.all;
  std::printf("%s", g.out.c_str());
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j["subjects"].size(), 1u);
  EXPECT_EQ(j["subjects"][0]["name"], "three/double");
  const auto& t = j["subjects"][0]["totals"];
  // three r187 (pinned by ci/fetch-corpus.sh) gave 58,320 tests, 0.0086%
  // wrong (3 false hits, 2 false misses), 0 leaks in 14,286 groups, 1 double
  // hit (README.md in validation/peers/). The bounds are an order of
  // magnitude above that, and leaks stay 0: its sheared edge functions are
  // evaluated alike for a shared edge, so no ray falls between two triangles.
  EXPECT_GT(t["tests"].get<std::uint64_t>(), 50000u);
  EXPECT_GT(t["groups"].get<std::uint64_t>(), 5000u);
  EXPECT_EQ(t["leaks"], 0) << g.out;
  EXPECT_LE(t["double_hits"].get<std::uint64_t>(), 10u) << g.out;
  EXPECT_LE(t["wrong_pct"].get<double>(), 0.1) << g.out;
  EXPECT_EQ(t["nan_inf"], 0) << g.out;
}
