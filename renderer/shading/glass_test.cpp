// Glass: POV-Ray 3.7's transparency, refraction and Fresnel formulas
// (shading/glass.h), the scene and MTL keys that set them, and the renderer
// seeing through a transparent sphere. Expected values are physics or the
// textbook formulas, not the code's own output.
#include "glass.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "../errors.h"
#include "../render.h"
#include "../scene/scene.h"

namespace ra {
namespace {

TEST(Glass, FresnelAtNormalIncidenceIsTheTextbookValue) {
  // ((n - 1) / (n + 1))^2 = 0.04 for n = 1.5.
  const auto f = glass::fresnel(1.5, 1.0);
  ASSERT_TRUE(f);
  EXPECT_NEAR(*f, 0.04, 1e-12);
}

TEST(Glass, FresnelGrowsToOneAtGrazingIncidence) {
  const auto steep = glass::fresnel(1.5, 0.9), grazing = glass::fresnel(1.5, 1e-4);
  ASSERT_TRUE(steep && grazing);
  EXPECT_LT(*steep, 0.1);
  EXPECT_GT(*grazing, 0.99);
}

TEST(Glass, FresnelBeyondTheCriticalAngleHasNoValue) {
  // Leaving glass (n2/n1 = 1/1.5) at cos 0.5: sin^2 = 0.75 > (1/1.5)^2.
  EXPECT_FALSE(glass::fresnel(1 / 1.5, 0.5));
}

TEST(Glass, RefractionObeysSnellsLaw) {
  const double eta = 1 / 1.5;  // entering glass
  const Vec3d D = normalize(Vec3d{std::sin(0.5), -std::cos(0.5), 0});
  const auto T = glass::refract(D, Vec3d{0, 1, 0}, eta);
  ASSERT_TRUE(T);
  const Vec3d t = normalize(*T);
  EXPECT_NEAR(std::sin(0.5), 1.5 * t.x, 1e-12);  // n1 sin(i) = n2 sin(t)
  EXPECT_LT(t.y, 0);                             // into the solid
  EXPECT_NEAR(length(*T), 1.0, 1e-12);
}

TEST(Glass, TotalInternalReflectionBeyondTheCriticalAngle) {
  // Leaving glass at 60 degrees: sin 60 * 1.5 > 1.
  const Vec3d D = normalize(Vec3d{std::sin(1.047), std::cos(1.047), 0});
  EXPECT_FALSE(glass::refract(D, Vec3d{0, -1, 0}, 1.5));
  EXPECT_TRUE(glass::refract(D, Vec3d{0, -1, 0}, 1.0));
}

TEST(Glass, InteriorListFollowsPovRaysRules) {
  auto ior = [](int o) { return o == 0 ? 1.5 : 1.2; };
  auto enter = glass::refraction_step({}, 0, ior);  // into object 0
  EXPECT_DOUBLE_EQ(enter.ior, 1 / 1.5);
  EXPECT_EQ(enter.interiors, std::vector<int>{0});
  auto nested = glass::refraction_step({0}, 1, ior);  // into 1 inside 0
  EXPECT_DOUBLE_EQ(nested.ior, 1.5 / 1.2);
  EXPECT_EQ(nested.interiors, (std::vector<int>{0, 1}));
  auto leave_inner = glass::refraction_step({0, 1}, 1, ior);  // out of 1, back in 0
  EXPECT_DOUBLE_EQ(leave_inner.ior, 1.2 / 1.5);
  auto overlap = glass::refraction_step({0, 1}, 0, ior);  // out of 0 while in 1
  EXPECT_DOUBLE_EQ(overlap.ior, 1.0);
  EXPECT_EQ(overlap.interiors, std::vector<int>{1});
  auto out = glass::refraction_step({0}, 0, ior);
  EXPECT_DOUBLE_EQ(out.ior, 1.5);
  EXPECT_TRUE(out.interiors.empty());
}

TEST(Glass, PassingLightIsColourTimesFilterPlusTransmit) {
  const Vec3d p = glass::rgb_transm({1, 0.5, 0}, 0.4, 0.2);
  EXPECT_DOUBLE_EQ(p.x, 0.6);
  EXPECT_DOUBLE_EQ(p.y, 0.4);
  EXPECT_DOUBLE_EQ(p.z, 0.2);
  EXPECT_DOUBLE_EQ(glass::opacity(0.4, 0.2), 0.4);
}

TEST(GlassScene, KeysAreReadAndOutOfRangeValuesRefused) {
  const Scene s = parse_scene_json(
      R"({"objects": [{"sphere": {}, "material": {"transmit": 0.5, "filter": 0.25, "ior": 1.33, "fresnel": true}}]})",
      "s.json");
  const Material& m = s.objects[0].material;
  EXPECT_EQ(m.transmit, 0.5);
  EXPECT_EQ(m.filter, 0.25);
  EXPECT_EQ(m.ior, 1.33);
  EXPECT_TRUE(m.fresnel);
  EXPECT_THROW(parse_scene_json(R"({"objects": [{"sphere": {}, "material": {"ior": 0}}]})", "s.json"), InputError);
  EXPECT_THROW(parse_scene_json(R"({"objects": [{"sphere": {}, "material": {"transmit": 1.01}}]})", "s.json"),
               InputError);
  EXPECT_THROW(parse_scene_json(R"({"objects": [{"sphere": {}, "material": {"filter": -0.5}}]})", "s.json"),
               InputError);
}

TEST(GlassScene, MtlDissolveIorAndIllumMapOntoTheMaterial) {
  // Named per process: the release and sanitizer suites may run at once.
  const auto dir = std::filesystem::temp_directory_path() / ("rayaudit-glass-mtl-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "g.mtl") << "newmtl g\nKd 0.2 0.4 0.6\nKs 0.9 0.9 0.9\nTr 0.75\nNi 1.45\nillum 7\n"
                               << "newmtl t\nKd 1 0 0\nTf 1 0 0\nd 0.5\nillum 4\nNi 1.7\n";
  std::ofstream(dir / "g.obj") << "mtllib g.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\nusemtl t\nf 1 3 2\n";
  std::ofstream(dir / "s.json") << R"({"objects": [{"mesh": "g.obj"}]})";
  const Scene s = load_scene(dir / "s.json");
  // The set's materials as its triangles use them (a default one may lead).
  const auto& set = *s.objects[0].mesh;
  ASSERT_EQ(set.triangles.size(), 2u);
  const std::vector<Material> mats{set.materials[std::size_t(set.triangles[0].material)],
                                   set.materials[std::size_t(set.triangles[1].material)]};
  EXPECT_DOUBLE_EQ(mats[0].transmit, 0.75);  // Tr 0.75: d = 0.25, transmit 1 - d
  EXPECT_EQ(mats[0].filter, 0);
  EXPECT_EQ(mats[0].ior, 1.45);
  EXPECT_TRUE(mats[0].fresnel);
  EXPECT_EQ(mats[0].reflection, (Vec3d{0.9, 0.9, 0.9}));
  EXPECT_EQ(mats[1].filter, 0.5);  // a tinted Tf: filter, tinted by Kd
  EXPECT_EQ(mats[1].transmit, 0);
  EXPECT_EQ(mats[1].ior, 1);  // illum 4 does not refract
  EXPECT_FALSE(mats[1].fresnel);
  std::filesystem::remove_all(dir);
}

// A fully transmitting, non-bending sphere in front of a red wall: the
// pixel through it is the wall's colour (the sphere adds nothing: no
// ambient, no diffuse), and with transmit 0 the sphere hides the wall.
TEST(GlassRender, ClearSphereShowsWhatIsBehindIt) {
  const char* base = R"({"width": 9, "height": 9, "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vfov": 20},
    "lights": [], "ambient_light": 1,
    "objects": [{"plane": {"normal": [0, 0, 1], "offset": -3}, "material": {"color": [1, 0, 0], "ambient": 1}},
                {"sphere": {"radius": 1}, "material": {"color": [0, 1, 0], "ambient": AMB, "diffuse": 0, "transmit": T}}]})";
  auto scene = [&](const char* amb, const char* t) {
    std::string j = base;
    j.replace(j.find("AMB"), 3, amb);
    j.replace(j.find("T}"), 1, t);
    return parse_scene_json(j, "s.json");
  };
  RenderOptions o;
  o.progress = false;
  const Scene clear = scene("0", "1");
  const Color c = Tracer(clear, o).pixel(4, 4);
  EXPECT_NEAR(c.x, 1, 1e-12);
  EXPECT_NEAR(c.y, 0, 1e-12);
  const Scene opaque = scene("1", "0");
  const Color d = Tracer(opaque, o).pixel(4, 4);
  EXPECT_NEAR(d.x, 0, 1e-12);
  EXPECT_NEAR(d.y, 1, 1e-12);
  // Half transmitted at both the front and the back surface: each adds half
  // its own light and passes half of what is behind it:
  // 0.5 G + 0.5 (0.5 G + 0.5 R).
  const Scene half = scene("1", "0.5");
  const Color h = Tracer(half, o).pixel(4, 4);
  EXPECT_NEAR(h.x, 0.25, 1e-12);
  EXPECT_NEAR(h.y, 0.75, 1e-12);
}

}  // namespace
}  // namespace ra
