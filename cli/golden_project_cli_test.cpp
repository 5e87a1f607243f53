// `rayaudit golden` in a user's own project: the project found from the
// current directory, hints that name it, diff folders kept out of every
// golden folder (symlinks resolved), per-scene size and tolerance, failure
// coordinates in scene pixels, the JSON, and `--image` judging another
// renderer's image against a golden.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "image.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::one_line;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

const std::string kSphereOnPlane = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/sphere-on-plane.json";

// Runs rayaudit with `dir` as the current directory.
ra::test::CliResult run_in(const fs::path& dir, const std::string& args) {
  return run_rayaudit(args, "cd '" + dir.string() + "' &&");
}

// Every file under `d`, with its bytes: what a refused command must leave as it was.
std::map<std::string, std::string> tree(const fs::path& d) {
  std::map<std::string, std::string> out;
  if (fs::exists(d))
    for (const auto& e : fs::recursive_directory_iterator(d))
      out[e.path().string()] = fs::is_regular_file(e.symlink_status()) ? slurp(e.path()) : "";
  return out;
}

// A user's project: scenes/s.json (sphere-on-plane, 320x240) and a small
// 8x8 one, t.json, both blessed from inside the project.
class GoldenProject : public ::testing::Test {
 protected:
  void SetUp() override {
    base = fs::temp_directory_path() / ("rayaudit-golden-project-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(base);
    root = base / "my project";  // a space: the hints quote it
    fs::create_directories(root / "scenes");
    fs::copy_file(kSphereOnPlane, root / "scenes" / "s.json");
    std::ofstream(root / "scenes" / "t.json")
        << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}, "material": {"color": 0.5}}]})"
        << "\n";
    const auto r = run_in(root / "scenes", "golden bless");
    ASSERT_EQ(r.code, 0) << r.all;
  }
  void TearDown() override { fs::remove_all(base); }
  // Changes golden pixel (x, y) of `png` by `by` levels in red.
  static void nudge(const fs::path& png, int x, int y, int by, const fs::path& to = {}) {
    ra::Image img = ra::read_image(png);
    float& red = img.at(x, y)[0];
    red = red + by / 255.0f > 1.0f ? red - by / 255.0f : red + by / 255.0f;
    ra::write_image(to.empty() ? png : to, img);
  }
  fs::path base, root;
};

TEST_F(GoldenProject, BlessAndCheckFromInsideTheProjectUseItsGoldens) {
  EXPECT_TRUE(fs::exists(root / "golden" / "manifest.json"));
  EXPECT_TRUE(fs::exists(root / "golden" / "s.png"));
  // From a folder below the project: its goldens, not this program's checkout.
  fs::create_directories(root / "build" / "deep");
  const auto r = run_in(root / "build" / "deep", "golden check t s --diff-dir '" + (base / "d").string() + "'");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("ok   t: identical to golden/t.png (8x8)"), std::string::npos) << r.out;
  // The default long side, 160 pixels, for the 320x240 scene.
  EXPECT_NE(r.out.find("ok   s: identical to golden/s.png (160x120)"), std::string::npos) << r.out;
  // A scene only this program's checkout has is not found here.
  const auto other = run_in(root, "golden check doc000-pyramid");
  EXPECT_EQ(other.code, 2) << other.all;
  EXPECT_EQ(other.err,
            (root / "scenes" / "doc000-pyramid.json").string() + ": no such file, and no golden of that name\n");
}

TEST_F(GoldenProject, OutsideAnyProjectCheckSaysHowTheProjectIsFound) {
  fs::create_directories(base / "elsewhere");
  const auto r = run_in(base / "elsewhere", "golden check t");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("no project here"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("golden/manifest.json or scenes/ (give --root)"), std::string::npos) << r.err;
  const auto help = run_rayaudit("golden --help");
  EXPECT_NE(help.out.find("from the current directory up, holding golden/manifest.json"), std::string::npos)
      << help.out;
  EXPECT_NE(help.out.find("160"), std::string::npos) << help.out;
}

// The hint names the project with --root, quoted: pasted in another folder,
// it blesses this project's golden, and the check then passes.
TEST_F(GoldenProject, FailureHintNamesTheRootAndWorksPastedElsewhere) {
  std::ofstream(root / "scenes" / "t.json")
      << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}, "material": {"color": 0.25}}]})"
      << "\n";
  auto r = run_in(root, "golden check t --diff-dir '" + (base / "d").string() + "'");
  EXPECT_EQ(r.code, 1) << r.all;
  const std::string hint = "rayaudit golden bless t --root '" + root.string() + "'";
  const auto at = r.out.find(hint);
  ASSERT_NE(at, std::string::npos) << r.out;
  fs::create_directories(base / "elsewhere");
  const auto pasted =
      run_rayaudit(hint.substr(std::string("rayaudit ").size()), "cd '" + (base / "elsewhere").string() + "' &&");
  EXPECT_EQ(pasted.code, 0) << pasted.all;
  EXPECT_EQ(run_in(root, "golden check t --diff-dir '" + (base / "d").string() + "'").code, 0);
}

// A --diff-dir in any golden folder, or one whose diff image would land on
// a golden, is refused before the work, one line, nothing written: also
// when reached through a symlink, and through a dangling one.
TEST_F(GoldenProject, DiffDirInAGoldenFolderIsRefusedAlsoThroughSymlinks) {
  // Another project beside this one, with its own goldens.
  const fs::path other = base / "other";
  fs::create_directories(other / "scenes");
  fs::copy_file(root / "scenes" / "t.json", other / "scenes" / "t.json");
  ASSERT_EQ(run_rayaudit("golden bless --root '" + other.string() + "'").code, 0);
  nudge(root / "golden" / "t.png", 3, 4, 10);  // so that a check would write its diff images
  fs::create_directory_symlink(other / "golden", base / "link");
  fs::create_directory_symlink(other / "golden" / "not-yet", base / "dangling");
  fs::create_directories(base / "files");
  fs::create_symlink(root / "golden" / "t.png", base / "files" / "t.png");  // the render's name, on a golden
  const auto before = tree(base);
  const std::string what = "--diff-dir is in the golden folder ";
  for (const auto& [dir, says] : std::vector<std::pair<fs::path, std::string>>{
           {other / "golden", what},
           {other / "golden" / "sub" / "deeper", what},
           {root / "golden", what},
           {base / "link", what},
           {base / "link" / "new", what},
           {base / "dangling", what},
           {base / "files", "t.png: would be written in the golden folder "}}) {
    const auto r = run_in(root, "golden check t --diff-dir '" + dir.string() + "'");
    EXPECT_EQ(r.code, 2) << dir << ": " << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind((base / "files").string() == dir.string() ? (dir / "t.png").string() : dir.string(), 0), 0u)
        << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "refused before the work";
    EXPECT_EQ(tree(base), before) << dir;
  }
}

// Size and tolerance per scene in the manifest; failure coordinates in
// scene pixels (the golden is half the scene's size here); the colour key
// with the diff; the JSON shaped as compare --json.
TEST_F(GoldenProject, ManifestSetsSizeAndToleranceAndFailuresSpeakScenePixels) {
  nudge(root / "golden" / "s.png", 10, 20, 3);  // golden pixel (10, 20): scene pixel (21, 41)
  const fs::path json = base / "g.json";
  auto r = run_in(root, "golden check s --diff-dir '" + (base / "d").string() + "' --json '" + json.string() + "'");
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("1 pixels differ (at most 0 allowed), by at most 3 levels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("at pixel (21, 41)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("first differences: (21, 41) 3 levels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("coordinates are scene pixels (of 320x240); the golden and diff images are 160x120"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("diff colours"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("green 2 to 4 levels"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(base / "d" / "s.diff.png"));
  const auto j = nlohmann::json::parse(slurp(json));
  ASSERT_EQ(j["scenes"].size(), 1u);
  const auto& s = j["scenes"][0];
  EXPECT_EQ(s["status"], "fail");
  EXPECT_EQ(s["within_tolerance"], false);
  EXPECT_EQ(s["width"], 160);
  EXPECT_EQ(s["scene_width"], 320);
  EXPECT_EQ(s["differing"], 1);
  ASSERT_EQ(s["differences"].size(), 1u);
  EXPECT_EQ(s["differences"][0],
            (nlohmann::json{{"x", 21}, {"y", 41}, {"golden_x", 10}, {"golden_y", 20}, {"levels", 3}}));
  EXPECT_EQ(s["max_error_pixel"]["x"], 21);
  EXPECT_EQ(s["diff_key"][2]["colour"], "green");
  EXPECT_EQ(j["diff_key"].size(), 5u);
  for (const char* k : {"bits", "pixels", "identical", "mean_error", "psnr", "verdict", "tolerance", "diff_image"})
    EXPECT_TRUE(s.contains(k)) << k;

  // A tolerance in the manifest lets it pass; a max_side of 40 makes the
  // next bless 40x30 (kept by it).
  auto m = nlohmann::json::parse(slurp(root / "golden" / "manifest.json"));
  for (auto& g : m["goldens"])
    if (g["name"] == "s") g["tolerance"] = {{"max_levels", 3}, {"max_pixels", 1}};
  std::ofstream(root / "golden" / "manifest.json") << m.dump(2);
  r = run_in(root, "golden check s --diff-dir '" + (base / "d").string() + "'");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("within the tolerance of golden/s.png"), std::string::npos) << r.out;
  for (auto& g : m["goldens"])
    if (g["name"] == "s") g["max_side"] = 40;
  std::ofstream(root / "golden" / "manifest.json") << m.dump(2);
  r = run_in(root, "golden bless s");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("size changed to 40x30"), std::string::npos) << r.out;
  m = nlohmann::json::parse(slurp(root / "golden" / "manifest.json"));
  for (auto& g : m["goldens"])
    if (g["name"] == "s") {
      EXPECT_EQ(g["max_side"], 40);
      EXPECT_EQ(g["tolerance"]["max_levels"], 3);
    }
  EXPECT_EQ(ra::read_image(root / "golden" / "s.png").width, 40);
}

// Another renderer's image against the golden: the golden itself passes, a
// copy with one pixel changed fails with its scene coordinates and a diff.
TEST_F(GoldenProject, ImageFromAnotherRendererIsJudgedAgainstTheGolden) {
  fs::copy_file(root / "golden" / "s.png", base / "theirs.png");
  auto r = run_in(root, "golden check --image '" + (base / "theirs.png").string() + "' s --diff-dir '" +
                            (base / "d").string() + "'");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("theirs.png identical to golden/s.png"), std::string::npos) << r.out;
  nudge(base / "theirs.png", 100, 50, 40);
  const fs::path json = base / "g.json";
  r = run_in(root, "golden check --image '" + (base / "theirs.png").string() + "' s --diff-dir '" +
                       (base / "d").string() + "' --json '" + json.string() + "'");
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("first differences: (201, 101) 40 levels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("red more than 16 levels"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(base / "d" / "s.diff.png"));
  EXPECT_FALSE(fs::exists(base / "d" / "s.png")) << "no render of ours is written with --image";
  const auto j = nlohmann::json::parse(slurp(json));
  EXPECT_EQ(j["against"], "image");
  EXPECT_EQ(j["scenes"][0]["image"], (base / "theirs.png").string());
  EXPECT_EQ(j["scenes"][0]["differences"][0]["levels"], 40);
}

// Images that cannot be judged pixel for pixel: one line naming the file,
// exit 2, nothing written.
TEST_F(GoldenProject, BadImagesAreRefusedNamingTheFile) {
  const ra::Image golden = ra::read_image(root / "golden" / "s.png");
  ra::Image small(80, 60);
  ra::write_image(base / "small.png", small);
  ra::write_image(base / "deep.png", golden, {16, false});
  ra::write_image(base / "srgb.png", golden, {8, true});
  std::ofstream(base / "text.png") << "not an image\n";
  fs::create_directories(base / "d");
  struct Case {
    std::string file, says;
  };
  for (const Case& c :
       {Case{"small.png", "is 80x60, but golden/s.png is 160x120"},
        Case{"deep.png", "has 16 bits a channel; golden/s.png has 8"}, Case{"srgb.png", "is tagged as "},
        Case{"text.png", "not a PNG file"}, Case{"missing.png", "no such file"}}) {
    const auto r = run_in(root, "golden check s --image '" + (base / c.file).string() + "' --diff-dir '" +
                                    (base / "d").string() + "' --json '" + (base / "g.json").string() + "'");
    EXPECT_EQ(r.code, 2) << c.file << ": " << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind((base / c.file).string() + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(base / "d"));
    EXPECT_FALSE(fs::exists(base / "g.json"));
  }
  const auto two = run_in(root, "golden check s t --image '" + (base / "small.png").string() + "'");
  EXPECT_EQ(two.code, 2) << two.all;
  EXPECT_TRUE(one_line(two.err)) << two.err;
}

}  // namespace
