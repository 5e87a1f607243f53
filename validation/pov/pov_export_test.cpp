// The POV-Ray exporter: what it writes, what it refuses, and that a scene
// cannot inject SDL through a file name (SDL can write files: #fopen/#write).
#include "pov_export.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "errors.h"
#include "pov_runner.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

bool povray_available() {
  try {
    find_povray();
    return true;
  } catch (const InputError&) {
    return false;
  }
}

fs::path fresh_dir(const std::string& tag) {
  // Under /tmp: Debian's povray.conf lets POV-Ray write there, so the
  // injection below would succeed if the exporter let it through.
  const fs::path d = fs::path("/tmp") / ("rayaudit-pov-test-" + tag + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A textured quad facing the default camera, with the texture file at `tex`.
Scene textured_quad(const fs::path& tex) {
  Scene s;
  s.width = 32;
  s.height = 24;
  s.file = tex.parent_path() / "quad.json";
  s.lights = {PointLight{{0, 0, 5}, {1, 1, 1}}};
  auto set = std::make_shared<TriangleSet>();
  set->name = "quad";
  set->positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  set->uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  set->triangles = {MeshTriangle3{{0, 1, 2}, {-1, -1, -1}, {0, 1, 2}, 0},
                    MeshTriangle3{{0, 2, 3}, {-1, -1, -1}, {0, 2, 3}, 0}};
  Material m;
  m.texture = ImageTexture{tex, TextureFilter::bilinear};
  set->materials = {m};
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  s.objects.push_back(o);
  return s;
}

void write_png(const fs::path& p) {
  Image img(4, 4);
  for (auto& v : img.rgb) v = 0.5f;
  fs::create_directories(p.parent_path());
  write_image(p, img);
}

TEST(PovStringLiteral, AcceptsGeneratedNames) { EXPECT_EQ(pov_string_literal("tex0.png"), "\"tex0.png\""); }

TEST(PovStringLiteral, RefusesAnythingThatCouldLeaveTheString) {
  for (const char* bad : {"a\"b", "a\\", "a\nb", "#fopen", "a{b", "x;y", "\x01", "caf\xc3\xa9"})
    EXPECT_THROW(pov_string_literal(bad), InputError) << bad;
}

TEST(PovExport, HorizontalFieldOfViewFromVertical) {
  EXPECT_NEAR(horizontal_fov_degrees(45, 1.0), 45, 1e-12);
  EXPECT_NEAR(horizontal_fov_degrees(90, 2.0), 2 * std::atan(2.0) * 180 / M_PI, 1e-12);
}

TEST(PovExport, WritesEveryFinishTermAndGlobalSetting) {
  Scene s;
  Object o;
  o.kind = Object::Kind::sphere;
  o.material.reflection = {0.5, 0.25, 0};
  s.objects.push_back(o);
  s.max_depth = 7;
  const std::string sdl = export_pov(s).sdl;
  for (const char* want : {"assumed_gamma 1.0", "max_trace_level 7", "adc_bailout 0.00392156862745098",
                           "ambient_light rgb <1,1,1>", "right <-1.3333333333333333,0,0>", "ambient rgb", "diffuse 0.6",
                           "brilliance 1", "phong 0", "phong_size 40", "specular 0", "reflection { rgb <0.5,0.25,0> }"})
    EXPECT_NE(sdl.find(want), std::string::npos) << want << "\n" << sdl;
}

TEST(PovExport, FlatMeshesGetNoNormalsAndSmoothOnesDo) {
  const fs::path dir = fresh_dir("normals");
  write_png(dir / "t.png");
  Scene s = textured_quad(dir / "t.png");
  std::string sdl = export_pov(s).sdl;
  EXPECT_EQ(sdl.find("normal_vectors"), std::string::npos);
  EXPECT_NE(sdl.find("uv_mapping"), std::string::npos);
  EXPECT_NE(sdl.find("png \"tex0.png\" gamma 1.0 interpolate 2"), std::string::npos) << sdl;
  s.objects[0].mesh->shading = Shading::smooth;
  sdl = export_pov(s).sdl;
  EXPECT_NE(sdl.find("normal_vectors { 4"), std::string::npos) << sdl;
  EXPECT_NE(sdl.find("normal_indices { 2"), std::string::npos) << sdl;
  fs::remove_all(dir);
}

TEST(PovExport, RefusesTheDocumentsOwnBumpVariants) {
  Scene s;
  Object o;
  o.kind = Object::Kind::sphere;
  o.material.bump = BumpMap{"b.png", BumpVariant::height, 1, TextureFilter::bilinear};
  s.objects.push_back(o);
  ASSERT_TRUE(pov_inexpressible(s).has_value());
  EXPECT_THROW(export_pov(s), InputError);
  s.objects[0].material.bump->variant = BumpVariant::pov;
  EXPECT_FALSE(pov_inexpressible(s).has_value());
}

// POV-Ray's image maps hold 8 or 16-bit integers: a texture stored as
// floats (an EXR) would be rounded, and clamped to [0, 1], by the export's
// PNG copy; such a scene is inexpressible, the same texture as a PNG is not.
TEST(PovExport, FloatTexturesAreInexpressible) {
  const fs::path dir = fresh_dir("floattex");
  Image img(4, 4);
  for (auto& v : img.rgb) v = 2.5f;
  write_image(dir / "bright.exr", img);
  write_png(dir / "plain.png");
  const auto reason = pov_inexpressible(textured_quad(dir / "bright.exr"));
  ASSERT_TRUE(reason.has_value());
  EXPECT_NE(reason->find("stores floating-point values"), std::string::npos) << *reason;
  EXPECT_THROW(export_pov(textured_quad(dir / "bright.exr")), InputError);
  EXPECT_FALSE(pov_inexpressible(textured_quad(dir / "plain.png")).has_value());
  fs::remove_all(dir);
}

// The texture's file name is SDL that opens and writes a file. The exporter
// must not let it through, and POV-Ray run on the export must not create the
// file. The control proves the payload is live: the same name written naively
// does create it.
TEST(PovExport, HostileTextureNameCannotInjectSdl) {
  if (!povray_available()) GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  const fs::path dir = fresh_dir("hostile");
  const fs::path target = dir / "pwn";
  const std::string name = "x.png\" } #fopen F \"" + target.string() + "\" write #write(F,\"x\") #declare A = {\"";
  const fs::path tex = dir / name;  // the slashes in the name make directories
  write_png(dir / "plain.png");
  fs::create_directories(tex.parent_path());
  fs::copy_file(dir / "plain.png", tex);
  ASSERT_TRUE(fs::exists(tex));
  const Scene s = textured_quad(tex);

  const PovExport ex = export_pov(s);
  EXPECT_EQ(ex.sdl.find("#fopen"), std::string::npos) << ex.sdl;
  EXPECT_EQ(ex.sdl.find("#write"), std::string::npos) << ex.sdl;
  EXPECT_EQ(ex.sdl.find(target.string()), std::string::npos) << ex.sdl;
  ASSERT_EQ(ex.images.size(), 1u);
  EXPECT_EQ(ex.images[0].name, "tex0.png");
  EXPECT_EQ(ex.images[0].source, tex);

  const PovRun run = render_with_povray(s);
  EXPECT_EQ(run.image.width, 32);
  EXPECT_FALSE(fs::exists(target)) << "POV-Ray created " << target << " from the export";

  // Control: the same name spliced into the SDL unescaped writes the file
  // (given an image where the truncated string points, so POV reads on).
  write_png(dir / "x.png");
  PovExport naive = ex;
  const std::string quoted = "\"tex0.png\"";
  naive.sdl.replace(naive.sdl.find(quoted), quoted.size(), "\"" + tex.string() + "\"");
  try {
    PovRunOptions quiet;
    quiet.keep_on_failure = false;
    run_povray(naive, 32, 24, quiet);
  } catch (const CheckFailed&) {
    // The injected SDL does not parse to the end; the file is written first.
  }
  EXPECT_TRUE(fs::exists(target)) << "the control did not create " << target << ": this test no longer proves anything";
  fs::remove_all(dir);
}

// An OBJ of points or lines gives a mesh without triangles: POV-Ray refuses
// an empty mesh2, so it is left out, and POV renders the background as we do
// (found by the corpus sweep on assimp's point_cloud.obj).
TEST(PovExport, MeshWithoutTrianglesIsLeftOut) {
  Scene s;
  s.width = 8;
  s.height = 6;
  s.background = {0.2, 0.4, 0.6};
  auto set = std::make_shared<TriangleSet>();
  set->name = "points.obj";
  set->positions = {{0, 0, 0}, {1, 0, 0}};
  set->materials.push_back(Material{});
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  s.objects.push_back(o);
  const PovExport ex = export_pov(s);
  EXPECT_EQ(ex.sdl.find("mesh2"), std::string::npos) << ex.sdl;
  if (!povray_available()) GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  const PovRun run = render_with_povray(s);
  EXPECT_NEAR(run.image.at(3, 2)[1], 0.4, 0.5 / 255);
}

}  // namespace
}  // namespace ra
