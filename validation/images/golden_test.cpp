// Golden images: bless records, check passes until the scene or the renderer
// changes, and a stale or missing golden is named as such.
#include "golden.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace ra {
namespace {

namespace fs = std::filesystem;

const char* kScene = R"({"width": 64, "height": 48, "lights": [{"position": [2, 3, 4]}],
  "objects": [{"sphere": {"center": [0, 0, 0], "radius": 1}, "material": {"color": [0.8, 0.3, 0.2]}}]})";

fs::path repo() {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-golden-test-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "scenes");
  std::ofstream(d / "scenes" / "ball.json") << kScene;
  return d;
}

TEST(Golden, MissingGoldenFailsAndSaysHowToBless) {
  const fs::path root = repo();
  const GoldenSet set(root);
  const auto r = set.check("ball", root / "diffs");
  EXPECT_FALSE(r.pass);
  EXPECT_NE(r.message.find("rayaudit golden bless ball"), std::string::npos) << r.message;
  fs::remove_all(root);
}

TEST(Golden, BlessThenCheckPassesAndAChangedSceneFailsWithADiffImage) {
  const fs::path root = repo();
  {
    GoldenSet set(root);
    EXPECT_NE(set.bless("ball").find("new golden"), std::string::npos);
    set.save();
  }
  EXPECT_TRUE(fs::exists(root / "golden" / "ball.png"));
  EXPECT_TRUE(GoldenSet(root).check("ball", root / "diffs").pass);

  // The scene changes: the image differs and the message says the inputs changed.
  std::string changed = kScene;
  changed.replace(changed.find("0.8, 0.3"), 8, "0.3, 0.8");
  std::ofstream(root / "scenes" / "ball.json") << changed;
  auto r = GoldenSet(root).check("ball", root / "diffs");
  EXPECT_FALSE(r.pass);
  EXPECT_NE(r.message.find("scenes/ball.json (changed)"), std::string::npos) << r.message;
  EXPECT_TRUE(fs::exists(root / "diffs" / "ball.diff.png"));

  // Only a change to the file that leaves the image alone: still stale.
  std::ofstream(root / "scenes" / "ball.json") << std::string(kScene) + "\n";
  r = GoldenSet(root).check("ball", root / "diffs");
  EXPECT_FALSE(r.pass);
  EXPECT_NE(r.message.find("stale"), std::string::npos) << r.message;
  {
    GoldenSet set(root);
    const std::string what = set.bless("ball");
    EXPECT_NE(what.find("image unchanged; inputs changed"), std::string::npos) << what;
    set.save();
  }
  EXPECT_TRUE(GoldenSet(root).check("ball", root / "diffs").pass);
  fs::remove_all(root);
}

TEST(Golden, SizeIsAtMostTheGoldenMaximumKeepingTheAspect) {
  const fs::path root = repo();
  std::string big = kScene;
  const std::string size = "\"width\": 64, \"height\": 48";
  big.replace(big.find(size), size.size(), "\"width\": 640, \"height\": 480");
  std::ofstream(root / "scenes" / "ball.json") << big;
  GoldenSet set(root);
  set.bless("ball");
  set.save();
  const Image img = read_image(root / "golden" / "ball.png");
  EXPECT_EQ(img.width, kGoldenMaxSize);
  EXPECT_EQ(img.height, kGoldenMaxSize * 3 / 4);
  fs::remove_all(root);
}

}  // namespace
}  // namespace ra
