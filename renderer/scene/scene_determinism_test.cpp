// Determinism: every shipped scene (scenes/*.json) renders to the
// same image with 1, 2 and 7 threads, and so does the mesh ladder
// (scenes/corpus/*.json) but for the 1M-triangle dragon. Scenes are rendered at 96 x 72 so the test stays
// fast; one whose mesh is in the corpus cache skips without it.
#include <gtest/gtest.h>

#include <filesystem>

#include "../errors.h"
#include "../render.h"
#include "scene.h"

namespace fs = std::filesystem;

namespace {

std::vector<std::string> shipped_scenes() {
  std::vector<std::string> out;
  const fs::path root = fs::path(RAYAUDIT_SOURCE_DIR) / "scenes";
  for (const fs::path& dir : {root, root / "corpus"})
    for (const auto& e : fs::directory_iterator(dir))
      // The 871k-triangle dragon (9 s here, its BVH built three times) is left to golden/corpus.
      if (e.path().extension() == ".json" && e.path().stem() != "ladder-1M-dragon")
        out.push_back((e.path().parent_path() == root ? "" : "corpus/") + e.path().stem().string());
  std::sort(out.begin(), out.end());
  return out;
}

class ShippedScene : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedScene, SameImageWith1And2And7Threads) {
  ra::Scene scene;
  try {
    scene = ra::load_scene(fs::path(RAYAUDIT_SOURCE_DIR) / "scenes" / (GetParam() + ".json"));
  } catch (const ra::InputError& e) {
    if (std::string(e.what()).find("corpus") != std::string::npos) GTEST_SKIP() << e.what();
    throw;
  }
  scene.width = 96;
  scene.height = 72;
  ra::apply_content_defaults(scene);
  ra::RenderOptions o;
  o.progress = false;
  o.threads = 1;
  const ra::Image one = ra::render(scene, o);
  bool varied = false;
  for (std::size_t i = 3; i < one.rgb.size() && !varied; ++i) varied = one.rgb[i] != one.rgb[i % 3];
  EXPECT_TRUE(varied) << "the image is not uniform (something is in view)";
  for (int n : {2, 7}) {
    o.threads = n;
    const ra::Image many = ra::render(scene, o);
    EXPECT_TRUE(many.rgb == one.rgb) << n << " threads";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ShippedScene, ::testing::ValuesIn(shipped_scenes()), [](const auto& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

}  // namespace
