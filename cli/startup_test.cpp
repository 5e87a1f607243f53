// Start-up cost: every process started at 132 MB and 0.14-0.27 s, even
// --version. OpenImageIO (~260 libraries, 130 MB) is loaded only by commands
// that touch an image (renderer/image_module.h). The dynamic loader's own
// log (LD_DEBUG=files) says which libraries a run mapped.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

const std::string kSource = RAYAUDIT_SOURCE_DIR;

bool loads_oiio(const std::string& loader_log) { return loader_log.find("file=libOpenImageIO") != std::string::npos; }

TEST(Startup, CommandsWithoutImagesDoNotLoadOpenImageIO) {
  for (const std::string& args : std::vector<std::string>{
           "--version", "methods", "info " + kSource + "/scenes/meshes/quad.obj", "audit --rays 200 --families edge"}) {
    const auto r = run_rayaudit(args, "LD_DEBUG=files");
    EXPECT_EQ(r.code, 0) << args << "\n" << r.all.substr(0, 2000);
    EXPECT_NE(r.err.find("file="), std::string::npos) << "no loader log for " << args;
    EXPECT_FALSE(loads_oiio(r.err)) << args << " loaded OpenImageIO";
  }
}

// The control: a textured render does load it, and writes its image.
TEST(Startup, ATexturedRenderLoadsTheImageModule) {
  const fs::path out = scratch("textured.png");
  const auto r = run_rayaudit(
      "render " + kSource + "/scenes/teapot-textured.json --width 32 --height 24 -o " + out.string(), "LD_DEBUG=files");
  EXPECT_EQ(r.code, 0) << r.all.substr(r.all.size() > 2000 ? r.all.size() - 2000 : 0);
  EXPECT_TRUE(loads_oiio(r.err));
  EXPECT_GT(fs::file_size(out), 100u);
  fs::remove_all(out.parent_path());
}

// Without the module: one line naming it, exit 2, before the render, and
// the existing output untouched.
TEST(Startup, AMissingImageModuleIsOneLineAndWritesNothing) {
  const fs::path out = scratch("kept.png");
  std::ofstream(out) << "good";
  const auto r = run_rayaudit("render " + kSource + "/scenes/doc000-pyramid.json -o " + out.string(),
                              "RAYAUDIT_IMAGE_MODULE=/nonexistent/rayaudit_image.so");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_EQ(r.err.rfind("rayaudit_image.so: the image module", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/rayaudit_image.so"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "good");
  fs::remove_all(out.parent_path());
}

}  // namespace
