// Tests of the random scenes and the shrinker of `rayaudit compare --random`
// (validation/pov/random_scene.h, validation/pov/pov_shrink.h).
#include "pov_shrink.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include <algorithm>

#include "pov_export.h"
#include "random_scene.h"

namespace ra {
namespace {

using json = nlohmann::json;

TEST(RandomScene, SameSeedAndIndexGiveTheSameSceneOthersDiffer) {
  EXPECT_EQ(random_scene(5, 3), random_scene(5, 3));
  EXPECT_NE(random_scene(5, 3), random_scene(5, 4));
  EXPECT_NE(random_scene(5, 3), random_scene(6, 3));
}

// The nightly's three seeds draw three different sets of scenes, not one
// set shuffled: the 600 scenes of seeds 1, 2 and 3 (200 each) are distinct.
TEST(RandomScene, NightlySeedsDrawDisjointSets) {
  std::set<std::string> seen;
  for (int seed : {1, 2, 3})
    for (int i = 0; i < 200; ++i)
      EXPECT_TRUE(seen.insert(random_scene(seed, i).dump()).second) << "scene " << seed << "-" << i << " repeats";
  EXPECT_EQ(seen.size(), 600u);
}

// Every generated scene is a valid scene file that POV-Ray can express, with
// 1 to 3 lights, a small image and at least one object.
TEST(RandomScene, ScenesParseAndExport) {
  int meshes = 0, spheres = 0, planes = 0, triangles = 0;
  for (int i = 0; i < 40; ++i) {
    const json j = random_scene(11, i);
    const Scene s = parse_scene_json(j.dump(), "random.json");
    EXPECT_GE(s.lights.size(), 1u);
    EXPECT_LE(s.lights.size(), 3u);
    EXPECT_LE(s.width * s.height, 160 * 120);
    EXPECT_GE(s.objects.size(), 1u);
    EXPECT_FALSE(pov_inexpressible(s).has_value());
    EXPECT_NO_THROW(export_pov(s));
    for (const auto& o : j["objects"]) {
      meshes += o.contains("mesh");
      spheres += o.contains("sphere");
      planes += o.contains("plane");
      triangles += o.contains("triangle");
    }
  }
  EXPECT_GT(spheres, 0);
  EXPECT_GT(planes, 0);
  EXPECT_GT(triangles, 0);
  if (!random_scene_meshes().empty()) {
    EXPECT_GT(meshes, 0);
  }
}

// A constructed case: the "unexplained pixel" persists exactly while the
// scene holds the red sphere and the second light. The shrinker must keep
// both and drop everything else it can.
TEST(Shrink, KeepsWhatThePixelNeedsAndDropsTheRest) {
  const json scene = json::parse(R"({
    "width": 40, "height": 30, "max_depth": 4, "background": [0.2, 0.3, 0.4],
    "lights": [{"position": [5, 5, 5], "color": [1, 0.5, 0.5]}, {"position": [-5, 5, 5]}],
    "objects": [
      {"plane": {"normal": [0, 1, 0], "offset": -1}, "material": {"reflection": 0.3}},
      {"sphere": {"center": [0, 0, 0], "radius": 0.7}, "material": {"color": [1, 0, 0], "phong": 0.5, "phong_size": 20}},
      {"triangle": [[0, 0, 1], [1, 0, 1], [0, 1, 1]]}
    ]})");
  auto holds = [](const json& s) {
    bool sphere = false, light = false;
    for (const auto& o : s.value("objects", json::array()))
      sphere |= o.contains("sphere") && o.contains("material") && o["material"].contains("color");
    for (const auto& l : s.value("lights", json::array())) light |= l["position"] == json::array({-5, 5, 5});
    return sphere && light;
  };
  int tries = 0;
  const json small = shrink_scene(scene, holds, 200, &tries);
  EXPECT_TRUE(holds(small));
  ASSERT_EQ(small["objects"].size(), 1u);
  EXPECT_TRUE(small["objects"][0].contains("sphere"));
  EXPECT_EQ(small["objects"][0]["material"], json::parse(R"({"color": [1, 0, 0]})"));
  ASSERT_EQ(small["lights"].size(), 1u);
  EXPECT_FALSE(small.contains("background"));
  EXPECT_EQ(small["max_depth"], 1);
  // Nothing more can go: every simplification of the result loses the pixel.
  for (const json& c : simplifications(small)) EXPECT_FALSE(holds(c)) << c.dump();
  EXPECT_GT(tries, 5);
}

// The minimal scene is written to read in one screen: short values on one
// line, and it reads back as the same scene.
TEST(Shrink, ReadableJsonIsShortAndTheSameScene) {
  const json j = random_scene(3, 1);
  const std::string text = readable_json(j);
  EXPECT_EQ(json::parse(text), j);
  auto count_lines = [](const std::string& t) { return int(std::count(t.begin(), t.end(), '\n')) + 1; };
  EXPECT_LT(2 * count_lines(text), count_lines(j.dump(2))) << text;  // not one number per line
  std::size_t longest = 0, start = 0;
  for (std::size_t i = 0; i <= text.size(); ++i)
    if (i == text.size() || text[i] == '\n') {
      longest = std::max(longest, i - start);
      start = i + 1;
    }
  EXPECT_LE(longest, 110u) << text;
}

}  // namespace
}  // namespace ra
