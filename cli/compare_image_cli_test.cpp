// `rayaudit compare SCENE --image THEIRS.png` against the real POV-Ray: a
// user's renderer's image of our scene judged against POV-Ray's render by
// the scene's tolerance, with the same diff and JSON; images that cannot be
// compared pixel for pixel are refused naming the file.
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

// sphere-on-plane at 64x48, in a folder of its own (no tolerance file
// beside it: the bar is identical at 8 bits), with POV-Ray's render of it.
class CompareImage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rayaudit-compare-image-" + std::to_string(::getpid()) + "-" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/sphere-on-plane.json", dir / "s.json");
    scene = (dir / "s.json").string() + " --width 64 --height 48";
    const auto r = run_rayaudit("compare " + scene + " --pov " + (dir / "pov.png").string());
    ASSERT_TRUE(r.code == 0 || r.code == 1) << r.all;
    ASSERT_TRUE(fs::exists(dir / "pov.png"));
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
  std::string scene;
};

TEST_F(CompareImage, PovRaysOwnRenderPassesAndAOnePixelChangeFailsWithItsCoordinates) {
  auto r = run_rayaudit("compare " + scene + " --image " + (dir / "pov.png").string());
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_NE(r.out.find("image: " + (dir / "pov.png").string() + " (against POV-Ray's render)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("identical: true"), std::string::npos) << r.out;

  ra::Image img = ra::read_image(dir / "pov.png");
  img.at(40, 30)[1] = img.at(40, 30)[1] > 0.5f ? img.at(40, 30)[1] - 6 / 255.0f : img.at(40, 30)[1] + 6 / 255.0f;
  ra::write_image(dir / "theirs.png", img);
  r = run_rayaudit("compare " + scene + " --image " + (dir / "theirs.png").string() + " --diff " +
                   (dir / "diff.png").string() + " --json " + (dir / "c.json").string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("pixel (40, 30) differs by 6 levels: NOT explained"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("diff colours"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("theirs.png differs from POV-Ray's"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "c.json"));
  EXPECT_EQ(j["image"], (dir / "theirs.png").string());
  EXPECT_EQ(j["within_tolerance"], false);
  EXPECT_EQ(j["differing"], 1);
  EXPECT_EQ(j["differences"][0], (nlohmann::json{{"x", 40}, {"y", 30}, {"levels", 6}}));
  EXPECT_EQ(j["diff_key"][3]["colour"], "yellow");
  EXPECT_EQ(ra::read_image(dir / "diff.png").width, 64);
}

TEST_F(CompareImage, BadImagesAreRefusedNamingTheFileBeforeAnyRender) {
  const ra::Image pov = ra::read_image(dir / "pov.png");
  ra::write_image(dir / "big.png", ra::Image(320, 240));
  ra::write_image(dir / "deep.png", pov, {16, false});
  ra::write_image(dir / "srgb.png", pov, {8, true});
  struct Case {
    std::string file, says;
  };
  for (const Case& c : {Case{"big.png", "is 320x240, but the scene's render (64x48, --bits 8) is 64x48"},
                        Case{"deep.png", "has 16 bits a channel"}, Case{"srgb.png", "is tagged as "},
                        Case{"missing.png", "no such file"}}) {
    const auto r = run_rayaudit("compare " + scene + " --image " + (dir / c.file).string() + " --json " +
                                (dir / "c.json").string() + " --diff " + (dir / "d.png").string());
    EXPECT_EQ(r.code, 2) << c.file << ": " << r.all;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_EQ(r.err.rfind((dir / c.file).string() + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "c.json"));
    EXPECT_FALSE(fs::exists(dir / "d.png"));
  }
  // At 16 bits the 16-bit image is the one that fits.
  const auto r = run_rayaudit("compare " + scene + " --bits 16 --image " + (dir / "pov.png").string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_NE(r.err.find("has 8 bits a channel; the scene's render (64x48, --bits 16) has 16"), std::string::npos)
      << r.err;
  // Writing over the image judged is refused as an input.
  const auto over = run_rayaudit("compare " + scene + " --image " + (dir / "pov.png").string() + " --diff " +
                                 (dir / "pov.png").string());
  EXPECT_EQ(over.code, 2) << over.all;
  EXPECT_TRUE(one_line(over.err)) << over.err;
}

// --explain on another renderer's image: where it equals our render, our
// models name the cause of its difference from POV-Ray's (the tetrahedron's
// one pixel, scenes/pov/doc002-tetrahedron.json); a pixel it changed on its
// own has none.
TEST(CompareImageExplain, OurModelsApplyWhereTheImageEqualsOurRender) {
  const fs::path dir = fs::temp_directory_path() / ("rayaudit-compare-image-explain-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(RAYAUDIT_SOURCE_DIR) + "/scenes/doc002-tetrahedron.json";
  auto r = run_rayaudit("compare " + scene + " --ours " + (dir / "ours.png").string());
  ASSERT_EQ(r.code, 0) << r.all;
  ra::Image img = ra::read_image(dir / "ours.png");
  img.at(5, 5)[0] = img.at(5, 5)[0] > 0.5f ? 0.0f : 1.0f;
  ra::write_image(dir / "theirs.png", img);
  r = run_rayaudit("compare " + scene + " --image " + (dir / "theirs.png").string() + " --explain --json " +
                   (dir / "c.json").string());
  EXPECT_EQ(r.code, 1) << r.all;
  EXPECT_NE(r.out.find("(166, 199) 1 levels: as rayaudit's render, equal normals"), std::string::npos) << r.out;
  const auto at = r.out.find("  (5, 5) ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NE(r.out.substr(at, r.out.find('\n', at) - at).find("levels: none of the known causes"), std::string::npos)
      << r.out;
  const auto j = nlohmann::json::parse(slurp(dir / "c.json"));
  ASSERT_EQ(j["explanations"].size(), 2u);
  fs::remove_all(dir);
}

}  // namespace
