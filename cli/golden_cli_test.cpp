// `rayaudit golden` as a user runs it, on a small repository of its own:
// a --diff-dir or --json that is an input or another output, a bless that
// fails half way, a manifest typo; a golden's size checked before the
// render, a large manifest read in linear time, a scene outside scenes/.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include <algorithm>

#include "io/full_disk.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

// ROOT/scenes/a.json and b.json: 8x8 spheres of two different colours.
void write_two_scenes(const fs::path& root) {
  fs::create_directories(root / "scenes");
  for (const char* n : {"a", "b"})
    std::ofstream(root / "scenes" / (std::string(n) + ".json"))
        << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}, "material": {"color": )"
        << (n[0] == 'a' ? "0.5" : "0.25") << "}}]}\n";
}

// A repository with two scenes, a and b, blessed; then a's golden image
// replaced by b's (same size, different pixels), so `check a` fails.
class GoldenDataCli : public ::testing::Test {
 protected:
  void SetUp() override {
    root = fs::temp_directory_path() / ("rayaudit-golden-cli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root);
    write_two_scenes(root);
    ASSERT_EQ(run_rayaudit("golden bless --root " + root.string()).code, 0);
    fs::copy_file(root / "golden" / "b.png", root / "golden" / "a.png", fs::copy_options::overwrite_existing);
    golden_a = slurp(root / "golden" / "a.png");
    manifest = slurp(root / "golden" / "manifest.json");
  }
  void TearDown() override { fs::remove_all(root); }
  fs::path root;
  std::string golden_a, manifest;
};

// The render written as DIFFDIR/a.png replaced golden/a.png, so the
// next check passed. Refused before the work; the golden untouched.
TEST_F(GoldenDataCli, DiffDirThatHoldsTheGoldensIsRefusedBeforeTheWork) {
  const auto r = run_rayaudit("golden check a --root " + root.string() + " --diff-dir " + (root / "golden").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind((root / "golden").string() + ": --diff-dir is in the golden folder ", 0), 0u) << r.err;
  EXPECT_EQ(r.out, "") << "refused before rendering";
  EXPECT_EQ(slurp(root / "golden" / "a.png"), golden_a);
  EXPECT_FALSE(fs::exists(root / "golden" / "a.diff.png"));
}

// --json naming one of the diff images lost the render.
TEST_F(GoldenDataCli, JsonNamingADiffImageIsRefusedAsTwoOutputs) {
  fs::create_directories(root / "out");
  const auto r = run_rayaudit("golden check a --root " + root.string() + " --diff-dir " + (root / "out").string() +
                              " --json " + (root / "out" / "a.png").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("is named as two outputs of this command"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(root / "out"));
}

// An empty --diff-dir (or --json) meant the default.
TEST_F(GoldenDataCli, EmptyDiffDirOrJsonIsRefused) {
  auto r = run_rayaudit("golden check a --root " + root.string() + " --diff-dir ''");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--diff-dir: empty value"), std::string::npos) << r.err;
  r = run_rayaudit("golden check a --root " + root.string() + " --json ''");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--json: empty value"), std::string::npos) << r.err;
}

// A failing check still writes its diff images and JSON (exit 1), into a
// --diff-dir it creates, with a folder for a scene name that holds one.
TEST_F(GoldenDataCli, FailingCheckWritesItsDiffImagesIntoANewDirectory) {
  const fs::path out = root / "new" / "diffs";
  const auto r = run_rayaudit("golden check a b --root " + root.string() + " --diff-dir " + out.string() + " --json " +
                              (root / "g.json").string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_TRUE(fs::exists(out / "a.diff.png"));
  EXPECT_TRUE(fs::exists(out / "a.png"));
  EXPECT_FALSE(fs::exists(out / "b.png")) << "b passed";
  EXPECT_NE(slurp(root / "g.json").find("\"fail\""), std::string::npos);
}

// A scene that fails to load after a failing one: exit 2 and none of the
// first one's diff images (outputs are renamed together at the end).
TEST_F(GoldenDataCli, CheckEndingInABadSceneWritesNothing) {
  std::ofstream(root / "scenes" / "b.json") << R"({"objects": [{"mesh": "nosuch.obj"}]})"
                                            << "\n";
  fs::create_directories(root / "out");
  const auto r = run_rayaudit("golden check a b --root " + root.string() + " --diff-dir " + (root / "out").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(fs::is_empty(root / "out"));
}

// A name that is neither a scene nor a golden is refused before any render
// (a was rendered first, then exit 2); a golden whose scene is gone is a
// failed check in its turn, not an error.
TEST_F(GoldenDataCli, UnknownSceneIsRefusedBeforeTheWork) {
  auto r = run_rayaudit("golden check b nosuch --root " + root.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.out, "") << "refused before rendering";
  EXPECT_EQ(r.err, (root / "scenes" / "nosuch.json").string() + ": no such file, and no golden of that name\n");
  fs::remove(root / "scenes" / "a.json");
  r = run_rayaudit("golden check a --root " + root.string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("is gone but its golden remains"), std::string::npos) << r.out;
}

// The same into a diff folder that is not there yet: the check makes it for
// a's images, then exits 2 on b; the new folders are removed again.
TEST_F(GoldenDataCli, CheckEndingInABadSceneLeavesNoNewDiffFolder) {
  std::ofstream(root / "scenes" / "b.json") << R"({"objects": [{"mesh": "nosuch.obj"}]})"
                                            << "\n";
  const fs::path out = root / "made" / "diffs";
  const auto r = run_rayaudit("golden check a b --root " + root.string() + " --diff-dir " + out.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_FALSE(fs::exists(root / "made")) << "a new, empty diff folder was left behind";
}

// `bless a BAD` rewrote a's golden, then failed on BAD: image and
// manifest disagreed. Now every scene is rendered before anything is written.
TEST_F(GoldenDataCli, BlessOfAGoodAndABadSceneWritesNothing) {
  std::ofstream(root / "scenes" / "z.json") << R"({"objects": [{"mesh": "nosuch.obj"}]})"
                                            << "\n";
  const auto r = run_rayaudit("golden bless a z --root " + root.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.out, "") << "nothing said blessed";
  EXPECT_EQ(slurp(root / "golden" / "a.png"), golden_a);
  EXPECT_EQ(slurp(root / "golden" / "manifest.json"), manifest);
  // And a good bless still rewrites it.
  const auto ok = run_rayaudit("golden bless a --root " + root.string());
  EXPECT_EQ(ok.code, 0) << ok.all;
  EXPECT_NE(ok.out.find("a: image changed"), std::string::npos) << ok.out;
  EXPECT_NE(slurp(root / "golden" / "a.png"), golden_a);
}

// Unknown keys and non-integer sizes in a manifest entry were ignored
// or coerced (1.5 -> 1, 2^63 -> 0); each is an error at its JSON path,
// quoting the file's value.
TEST_F(GoldenDataCli, ManifestEntriesAreReadStrictly) {
  struct Case {
    std::string from, to, says;
  };
  const Case cases[] = {
      {"\"bits\": 8", "\"bits\": 8, \"zzz\": 1", "/goldens/0/zzz: unknown key"},
      {"\"bits\": 8", "\"bits\": 8, \"spp\": 0", "/goldens/0/spp: unknown key"},
      {"\"width\": 8", "\"width\": 1.5", "/goldens/0/width: expected an integer, got 1.5"},
      {"\"width\": 8", "\"width\": true", "/goldens/0/width: expected an integer, got true"},
      {"\"width\": 8", "\"width\": 9223372036854775808",
       "/goldens/0/width: 9223372036854775808 is not 1 to 16384 pixels"},
      {"\"spp\": 1", "\"spp\": 3", "/goldens/0/settings/spp: spp must be a square number"},
      {"\"accel\": \"bvh\"", "\"accel\": \"fast\"", "/goldens/0/settings/accel: unknown accel \"fast\""},
      {"\"spp\": 1", "\"spp\": 1, \"zz\": 0", "/goldens/0/settings/zz: unknown key"},
      // Taken on trust before: a top-level key of no meaning,
      // a scene that is another golden's, two goldens sharing one image.
      {"\"goldens\":", "\"extra\": 1, \"goldens\":", "/extra: unknown key"},
      {"\"scene\": \"scenes/a.json\"", "\"scene\": \"scenes/b.json\"",
       "/goldens/0: scene \"scenes/b.json\" is not this golden's, scenes/a.json"},
      {"\"image\": \"golden/b.png\"", "\"image\": \"golden/a.png\"",
       "/goldens/1: image \"golden/a.png\" is golden \"a\"'s too"},
  };
  for (const Case& c : cases) {
    std::string m = manifest;
    const auto at = m.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from << " in\n" << manifest;
    m.replace(at, c.from.size(), c.to);
    std::ofstream(root / "golden" / "manifest.json") << m;
    const auto r = run_rayaudit("golden check a --root " + root.string());
    EXPECT_EQ(r.code, 2) << c.to << ": " << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    // FILE:LINE: the line of the value (or key) in the manifest.
    const std::string file = (root / "golden" / "manifest.json").string() + ":";
    EXPECT_EQ(r.err.rfind(file, 0), 0u) << r.err;
    EXPECT_TRUE(r.err.size() > file.size() && std::isdigit(static_cast<unsigned char>(r.err[file.size()]))) << r.err;
    EXPECT_NE(r.err.find(": " + c.says), std::string::npos) << r.err;
  }
}

// `bless` on a full disk replaced the golden image, then failed to
// write the manifest: image and manifest disagreed. All are renamed
// together after the last is written, so exit 2 leaves golden/ as it was.
TEST(GoldenFullDiskCli, BlessOnAFullDiskLeavesGoldenAsItWas) {
  ra::test::FullDisk disk(32 * 1024);
  if (!disk.ok()) GTEST_SKIP() << disk.why_not();
  const fs::path root = disk.dir() / "repo";
  write_two_scenes(root);
  ASSERT_EQ(run_rayaudit("golden bless --root " + root.string()).code, 0);
  fs::copy_file(root / "golden" / "b.png", root / "golden" / "a.png", fs::copy_options::overwrite_existing);
  const std::string image = slurp(root / "golden" / "a.png"), manifest = slurp(root / "golden" / "manifest.json");
  // Fill the disk with pages, then free one: one temporary fits, not two.
  int pages = 0;
  for (;; ++pages) {
    std::ofstream f(disk.dir() / ("fill" + std::to_string(pages)), std::ios::binary);
    f << std::string(4096, 'x');
    f.flush();
    if (!f) break;
  }
  ASSERT_GT(pages, 0);
  fs::remove(disk.dir() / "fill0");
  fs::remove(disk.dir() / ("fill" + std::to_string(pages)));
  const auto r = run_rayaudit("golden bless a --root " + root.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(root / "golden" / "a.png"), image);
  EXPECT_EQ(slurp(root / "golden" / "manifest.json"), manifest);
  for (const auto& e : fs::directory_iterator(root / "golden"))
    EXPECT_NE(e.path().filename().string().rfind(".tmp-", 0), 0u) << "left behind: " << e.path();
}

// A fresh repository in the scratch directory NAME: scenes/t.json (an 8x8
// sphere) and an empty golden/.
fs::path sphere_repo(const std::string& name) {
  const fs::path root = scratch(name);
  fs::remove_all(root);
  fs::create_directories(root / "scenes");
  fs::create_directories(root / "golden");
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 1}}]})"
                                            << "\n";
  return root;
}

// A golden manifest claiming 16384x16384 for an 8x8 golden: the golden's
// size is compared first, not after a 3.3 GB render of the claimed size
// (which a 1 GB address-space limit turns into a failed allocation).
TEST(GoldenCli, GoldenSizeIsComparedBeforeRenderingTheManifestsSize) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path root = sphere_repo("golden-size");
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  std::string manifest = slurp(root / "golden" / "manifest.json");
  for (const char* key : {"\"width\": ", "\"height\": "}) {
    const auto at = manifest.find(key) + std::string(key).size();
    manifest.replace(at, manifest.find_first_of(",\n", at) - at, "16384");
  }
  std::ofstream(root / "golden" / "manifest.json") << manifest;
  const auto r = run_rayaudit("golden check --root " + root.string() + " --diff-dir " + (root / "d").string(),
                              "prlimit --as=1000000000 --");
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.all.find("but the manifest says 16384x16384"), std::string::npos) << r.all;
}

// The JSON reader records a line for every value of a golden manifest: it
// counted each from the start of the file (2,000 entries took 12.8 s, 100k
// hours). 20,000 entries, the last with a misspelt key, are read within a
// CPU limit linear reading meets many times over, the error at its line.
TEST(GoldenCli, ManifestOf20kEntriesIsReadInLinearTime) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path root = sphere_repo("golden-lines");
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  const nlohmann::json m = nlohmann::json::parse(slurp(root / "golden" / "manifest.json"));
  nlohmann::json many = m;
  many["goldens"] = nlohmann::json::array();
  for (int i = 0; i < 20000; ++i) {
    nlohmann::json e = m["goldens"][0];
    e["name"] = "t" + std::to_string(i);
    e["scene"] = "scenes/t" + std::to_string(i) + ".json";  // each its own scene and image, as bless writes them
    e["image"] = "golden/t" + std::to_string(i) + ".png";
    many["goldens"].push_back(e);
  }
  many["goldens"].back()["widht"] = 8;
  const std::string text = many.dump(2);
  const std::size_t key = text.rfind("\"widht\"");
  ASSERT_NE(key, std::string::npos);
  const long line = 1 + long(std::count(text.begin(), text.begin() + std::ptrdiff_t(key), '\n'));
  std::ofstream(root / "golden" / "manifest.json") << text;
  const fs::path manifest = root / "golden" / "manifest.json";
  const auto r = run_rayaudit("golden check --root " + root.string(), "prlimit --cpu=10 --");
  EXPECT_EQ(r.code, 2) << r.all.substr(0, 300);
  EXPECT_EQ(r.err.rfind(manifest.string() + ":" + std::to_string(line) + ": ", 0), 0u) << r.err.substr(0, 300);
  EXPECT_TRUE(one_line(r.err)) << r.err.substr(0, 300);
}

// `golden check --diff-dir ROOT/golden` replaced the
// golden it compared against with this render (the next check passed);
// --json naming a diff image lost the render; `golden bless A BAD` rewrote
// A's image and failed on BAD, leaving the manifest stale.
TEST(GoldenCli, GoldenOutputsNeverReplaceInputsAndBlessIsAllOrNothing) {
  const fs::path root = sphere_repo("golden-io");
  fs::create_directories(root / "out");
  ASSERT_EQ(run_rayaudit("golden bless t --root " + root.string()).code, 0);
  // A golden that differs from the render: a check fails and writes its images.
  std::ofstream(root / "scenes" / "t.json") << R"({"width": 8, "height": 8, "objects": [{"sphere": {"radius": 0.5}}]})"
                                            << "\n";
  const std::string golden = slurp(root / "golden" / "t.png"), manifest = slurp(root / "golden" / "manifest.json");
  auto r = run_rayaudit("golden check t --root " + root.string() + " --diff-dir " + (root / "golden").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("--diff-dir is in the golden folder"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(root / "golden" / "t.png"), golden);
  EXPECT_FALSE(fs::exists(root / "golden" / "t.diff.png"));

  r = run_rayaudit("golden check t --root " + root.string() + " --diff-dir " + (root / "out").string() + " --json " +
                   (root / "out" / "t.png").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find("is named as two outputs of this command"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(root / "out"));

  std::ofstream(root / "scenes" / "zbad.json") << R"({"objects": [{"mesh": "meshes/nosuch.obj"}]})"
                                               << "\n";
  r = run_rayaudit("golden bless t zbad --root " + root.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find("zbad.json: /objects/0/mesh: file not found"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(root / "golden" / "t.png"), golden) << "rewritten although the bless failed";
  EXPECT_EQ(slurp(root / "golden" / "manifest.json"), manifest);
  fs::remove_all(root);
}

// `golden check /elsewhere/x.json` checked ROOT/scenes/x.json
// and named that file; a path outside scenes/ is refused as such, and an
// absolute path inside it is its scene.
TEST(GoldenCli, GoldenCheckOfAPathOutsideScenesIsNamedAsSuch) {
  const std::string root = RAYAUDIT_SOURCE_DIR;
  auto r = run_rayaudit("golden check /tmp/any/where/x.json --root " + root);
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err.rfind("/tmp/any/where/x.json: not a scene under ", 0), 0u) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  r = run_rayaudit("golden check " + root + "/scenes/doc000-pyramid.json --root " + root + " --diff-dir " +
                   scratch("gd").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("ok   doc000-pyramid: identical"), std::string::npos) << r.out;
}

}  // namespace
