// Scene files: defaults, and errors that name the file, JSON path and line.
#include "scene.h"

#include <gtest/gtest.h>

#include "../errors.h"

namespace ra {
namespace {

std::string error_of(const std::string& json) {
  try {
    parse_scene_json(json, "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SceneFile, EmptyObjectGivesTheDocumentedDefaults) {
  Scene s = parse_scene_json("{}", "s.json");
  EXPECT_EQ(s.width, 320);
  EXPECT_EQ(s.height, 240);
  EXPECT_EQ(s.max_depth, 5);
  EXPECT_EQ(s.background, Color(0, 0, 0));
  ASSERT_EQ(s.lights.size(), 1u);  // one white light at the camera
  EXPECT_EQ(s.lights[0].position, s.camera.position);
}

TEST(SceneFile, MaterialDefaultsArePovRays) {
  Scene s = parse_scene_json(R"({"objects": [{"sphere": {}}]})", "s.json");
  ASSERT_EQ(s.objects.size(), 1u);
  const Material& m = s.objects[0].material;
  EXPECT_EQ(m.ambient, Color(0.1, 0.1, 0.1));
  EXPECT_EQ(m.diffuse, 0.6);
  EXPECT_EQ(m.phong, 0.0);
  EXPECT_EQ(m.phong_size, 40.0);
  EXPECT_EQ(s.objects[0].sphere.radius, 1.0);
}

TEST(SceneFile, CameraFramesTheBoundingSphereWhenNotGiven) {
  Scene s = parse_scene_json(R"({"objects": [{"sphere": {"center": [1, 2, 3], "radius": 2}}]})", "s.json");
  EXPECT_EQ(s.camera.look_at, Vec3d(1, 2, 3));
  // The sphere (radius 2) fills the 45-degree view with a 10% margin.
  const double dist = length(s.camera.position - s.camera.look_at);
  EXPECT_NEAR(dist * std::sin(22.5 * M_PI / 180), 2.2, 1e-12);
}

TEST(SceneFile, UnknownKeyNamesItsPath) {
  EXPECT_EQ(error_of(R"({"objects": [{"sphere": {"radius": 1, "centre": [0,0,0]}}]})"),
            "s.json: /objects/0/sphere/centre: unknown key");
}

TEST(SceneFile, WrongTypeNamesItsPath) {
  EXPECT_EQ(error_of(R"({"camera": {"vfov": "wide"}})"), "s.json: /camera/vfov: expected a number, got string");
  // POV-Ray's camera refuses |look_at - position|^2 < 1e-10; so does ours.
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 1e-6], "look_at": [0, 0, 0]}})"),
            "s.json: /camera/look_at: must be at least 1e-5 from the position (POV-Ray refuses a nearer one)");
  EXPECT_EQ(error_of(R"({"lights": [{"position": [1, 2]}]})"),
            "s.json: /lights/0/position: expected an array of 3 numbers");
}

TEST(SceneFile, SyntaxErrorNamesTheLine) {
  const std::string e = error_of("{\n  \"width\": 10,\n  \"height\": ,\n}");
  EXPECT_EQ(e.rfind("s.json:3: invalid JSON", 0), 0u) << e;
}

TEST(SceneFile, MissingFileIsAnInputError) {
  EXPECT_THROW(load_scene("/nonexistent/scene.json"), InputError);
  EXPECT_NE(error_of(R"({"objects": [{"mesh": "nope.obj"}]})").find("/objects/0/mesh: file not found"),
            std::string::npos);
}

TEST(SceneFile, ObjectNeedsExactlyOneKind) {
  EXPECT_NE(error_of(R"({"objects": [{"sphere": {}, "plane": {}}]})").find("exactly one of"), std::string::npos);
}

TEST(SceneFile, AbsurdSizesAreRefused) {
  EXPECT_EQ(error_of(R"({"width": 100000})"), "s.json: /width: must be between 1 and 16384");
}

}  // namespace
}  // namespace ra
