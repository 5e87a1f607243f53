// Command-line options checked before any work, run through the real
// program: empty values and list items, out-of-range seeds, options that do
// not fit the output's format or each other.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

TEST(OptionsCli, VersionEndsWithANewline) {
  const auto r = run_rayaudit("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, std::string("rayaudit ") + RAYAUDIT_VERSION + "\n");
}

// PNG options with an EXR output were ignored (the file identical with or
// without them); refused as other ignored options are.
TEST(OptionsCli, PngOptionsWithAnExrAreRefused) {
  const fs::path out = scratch("png_opts.exr");
  for (const char* opt : {"--srgb", "--bits 16"}) {
    const auto r = run_rayaudit("render " + kScenes + "/meshes/tetrahedron.obj -o " + out.string() +
                                " --width 8 --height 8 " + opt);
    EXPECT_EQ(r.code, 2) << opt;
    EXPECT_EQ(r.err, out.string() + ": --srgb and --bits apply to PNG; an EXR holds the linear float values\n") << opt;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(OptionsCli, SeedOf2To64IsRefusedNotSaturated) {
  const auto r = run_rayaudit("audit --rays 10 --seed 18446744073709551616");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("at most 18446744073709551615"), std::string::npos) << r.err;
  EXPECT_EQ(run_rayaudit("audit --rays 10 --methods moller --seed 18446744073709551615").code, 0);
}

// An empty item in a list option was dropped (`--offsets 1,,2`), and an
// empty list meant "all" (`--methods ''`, `--families ,`): both refused.
TEST(OptionsCli, ListOptionsWithAnEmptyItemAreRefused) {
  const fs::path out = scratch("list.json");
  struct Case {
    std::string args, says;
  };
  for (const Case& c : std::vector<Case>{
           {"audit --rays 5 --families edge,,vertex --json " + out.string(),
            "--families: empty item in the list 'edge,,vertex'"},
           {"audit --rays 5 --families , --json " + out.string(), "--families: empty item in the list ','"},
           {"audit --rays 5 --methods moller, --json " + out.string(), "--methods: empty item in the list 'moller,'"},
           {"audit --rays 5 --precision float, --json " + out.string(), "--precision: empty item in the list 'float,'"},
           {"audit --rays 5 --methods '' --json " + out.string(), "--methods: empty list"},
           {"crack-maps -o " + scratch("cm-list").string() + " --offsets 1,,2",
            "--offsets: empty item in the list '1,,2'"}}) {
    const auto r = run_rayaudit(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(scratch("cm-list")));
}

// `audit --json ""` wrote nothing and exited 0; every
// option given an empty value is refused by name before any work.
TEST(OptionsCli, EmptyOptionValuesAreRefusedByName) {
  const fs::path dir = scratch("empty-values");
  fs::create_directories(dir);
  const std::string scene = kScenes + "/doc002-tetrahedron.json";
  const std::pair<std::string, std::string> cases[] = {
      {"audit --methods moller --families edge --rays 10 --json ''", "--json"},
      {"audit --methods moller --families edge --rays 10 --csv ''", "--csv"},
      {"audit --methods moller --families edge --rays 10 --export-cases ''", "--export-cases"},
      {"render " + scene + " -o ''", "--output"},
      {"compare " + scene + " --width 8 --height 8 --diff ''", "--diff"},
      {"convert " + kScenes + "/meshes/quad.obj -o ''", "--output"},
      {"golden check --root " + std::string(RAYAUDIT_SOURCE_DIR) + " --diff-dir '' doc002-tetrahedron", "--diff-dir"},
      {"render '' -o " + (dir / "x.png").string(), "scene"},
  };
  for (const auto& [args, flag] : cases) {
    const auto r = run_rayaudit(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(flag + ": empty value"), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

// A second precision for --export-cases was dropped
// silently (a file of double cases, exit 0); `--version extra` exited 0.
TEST(OptionsCli, ExportCasesWithTwoPrecisionsAndVersionWithAnArgumentAreRefused) {
  const fs::path out = scratch("two-precisions.csv");
  auto r = run_rayaudit("audit --export-cases " + out.string() + " --precision float,double --rays 10");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err, "--precision: --export-cases takes one precision (float or double), got 'float,double'\n");
  EXPECT_FALSE(fs::exists(out));
  r = run_rayaudit("audit --export-cases " + out.string() + " --precision float --rays 10");
  EXPECT_EQ(r.code, 0) << r.all;
  r = run_rayaudit("--version extra");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_TRUE(r.out.empty());
  fs::remove(out);
}

}  // namespace
