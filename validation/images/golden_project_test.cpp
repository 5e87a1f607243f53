// The golden project's rules in isolation: which folder is the project,
// real paths through relative, absolute, chained and dangling symlinks,
// which outputs fall in a golden folder, and shell quoting of hints.
#include "golden_project.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace fs = std::filesystem;

namespace {

class GoldenProjectRules : public ::testing::Test {
 protected:
  void SetUp() override {
    d = fs::temp_directory_path() / ("rayaudit-golden-rules-" + std::to_string(::getpid()) + "-" +
                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(d);
    fs::create_directories(d);
    d = fs::canonical(d);
  }
  void TearDown() override { fs::remove_all(d); }
  fs::path d;
};

TEST_F(GoldenProjectRules, NearestManifestFirstThenNearestScenesFolder) {
  fs::create_directories(d / "outer" / "golden");
  std::ofstream(d / "outer" / "golden" / "manifest.json") << "{}";
  fs::create_directories(d / "outer" / "inner" / "scenes");
  fs::create_directories(d / "outer" / "inner" / "build" / "x");
  // A manifest further up wins over a scenes/ folder nearer.
  EXPECT_EQ(ra::find_golden_project(d / "outer" / "inner" / "build" / "x"), d / "outer");
  fs::remove(d / "outer" / "golden" / "manifest.json");
  EXPECT_EQ(ra::find_golden_project(d / "outer" / "inner" / "build" / "x"), d / "outer" / "inner");
  EXPECT_EQ(ra::find_golden_project(d / "outer" / "inner" / "scenes"), d / "outer" / "inner");
  // The scenes folder must be a folder; a golden/manifest.json a file.
  fs::create_directories(d / "f" / "golden" / "manifest.json");
  std::ofstream(d / "f" / "scenes") << "";
  fs::create_directories(d / "f" / "sub");
  const auto found = ra::find_golden_project(d / "f" / "sub");
  EXPECT_TRUE(!found || (*found != d / "f" && *found != d / "f" / "sub")) << *found;
}

TEST_F(GoldenProjectRules, RealPathResolvesEveryLinkAlsoDangling) {
  fs::create_directories(d / "real" / "golden");
  fs::create_directory_symlink("real/golden", d / "rel");  // relative
  fs::create_directory_symlink(d / "rel", d / "chain");    // a link to a link
  fs::create_directory_symlink(d / "real" / "golden" / "none", d / "dangling");
  fs::create_symlink("loop", d / "loop");
  EXPECT_EQ(ra::real_path(d / "rel" / "a" / "b.png"), d / "real" / "golden" / "a" / "b.png");
  EXPECT_EQ(ra::real_path(d / "chain" / "x"), d / "real" / "golden" / "x");
  EXPECT_EQ(ra::real_path(d / "dangling" / "x"), d / "real" / "golden" / "none" / "x");
  EXPECT_EQ(ra::real_path(d / "real" / ".." / "rel"), d / "real" / "golden");
  (void)ra::real_path(d / "loop" / "x");  // ends; no answer promised
}

TEST_F(GoldenProjectRules, GoldenFoldersAreTheProjectsOwnAndAnyWithAManifest) {
  fs::create_directories(d / "p" / "scenes");
  fs::create_directories(d / "q" / "golden");
  std::ofstream(d / "q" / "golden" / "manifest.json") << "{}";
  fs::create_directories(d / "r" / "golden");  // no manifest: an ordinary folder named golden
  EXPECT_EQ(ra::golden_folder_of(d / "p" / "golden" / "new", d / "p"), d / "p" / "golden");
  EXPECT_EQ(ra::golden_folder_of(d / "q" / "golden" / "x" / "a.png", d / "p"), d / "q" / "golden");
  EXPECT_EQ(ra::golden_folder_of(d / "r" / "golden" / "a.png", d / "p"), std::nullopt);
  EXPECT_EQ(ra::golden_folder_of(d / "p" / "diffs", d / "p"), std::nullopt);
  fs::create_directory_symlink(d / "q" / "golden", d / "p" / "diffs");
  EXPECT_EQ(ra::golden_folder_of(d / "p" / "diffs", d / "p"), d / "q" / "golden");
}

TEST(ShellQuoted, PastesBackAsTheSameWord) {
  EXPECT_EQ(ra::shell_quoted("/tmp/my project"), "'/tmp/my project'");
  EXPECT_EQ(ra::shell_quoted("it's"), "'it'\\''s'");
  EXPECT_EQ(ra::shell_quoted(""), "''");
}

}  // namespace
