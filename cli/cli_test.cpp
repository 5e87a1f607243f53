// The real rayaudit program, run as a user runs it: exit codes, messages,
// and no output file on failure.
#include <gtest/gtest.h>

#include "run_rayaudit.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "image.h"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string out;  // stdout and stderr
};

Result run(const std::string& args) {
  const auto r = ra::test::run_rayaudit(args);
  return {r.code, r.all};
}

fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("rayaudit-cli-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(Cli, MissingSceneExits2AndWritesNothing) {
  const fs::path out = temp_dir() / "x.png";
  const Result r = run("render missing.json -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("missing.json"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, RendersTheShippedSceneToAPng) {
  const fs::path out = temp_dir() / "sphere.png";
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       out.string() + " --width 64 --height 48");
  ASSERT_EQ(r.code, 0) << r.out;
  const ra::Image img = ra::read_image(out);
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
  // The centre of the image is the red sphere: red dominates.
  const float* c = img.at(32, 24);
  EXPECT_GT(c[0], c[1] + 0.1f);
  // No temporary file is left beside the output.
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp-", 0), std::string::npos) << e.path();
}

TEST(Cli, BadSceneExits2WithFileAndPath) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "bad.json") << R"({"objects": [{"sphere": {"radius": -1}}]})";
  const Result r = run("render " + (dir / "bad.json").string() + " -o " + (dir / "bad.png").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("bad.json: /objects/0/sphere/radius: must be greater than 0"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "bad.png"));
}

TEST(Cli, UnknownMethodExits2ListingTheValidOnes) {
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       (temp_dir() / "m.png").string() + " --method nosuch");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("moller"), std::string::npos) << r.out;
}

TEST(Cli, UsageErrorsExit2AndHelpExits0) {
  EXPECT_EQ(run("render").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("render --help").code, 0);
  EXPECT_EQ(run("methods --help").code, 0);
  const Result v = run("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_NE(v.out.find("rayaudit"), std::string::npos);
}

TEST(Cli, NonSquareSppIsRefused) {
  const Result r = run(std::string("render ") + RAYAUDIT_SOURCE_DIR + "/scenes/sphere-on-plane.json -o " +
                       (temp_dir() / "spp.png").string() + " --spp 3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--spp"), std::string::npos) << r.out;
}

}  // namespace
