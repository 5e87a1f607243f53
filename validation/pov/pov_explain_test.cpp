// --explain against the real POV-Ray 3.7 on the cases it was made for: the
// Cornell box's 255-level pixel on the light quad's edge (POV's own mesh2
// inside test), and random scene 3-179's pixel decided by POV's float32
// Perp vector of smooth mesh2 triangles.
#include "pov_explain.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "errors.h"
#include "images/image_compare.h"
#include "pov_runner.h"
#include "images/golden.h"
#include "scene/scene.h"
#include "scene/scene_mesh.h"

namespace ra {
namespace {

// The float32 colour cause explains a pixel only where every channel that
// differs is one level off and ours lies at k + 0.5 within float32 ulps:
// 0.1f is 25.5000004 levels, so POV's float32 25 is explained; a hit
// against POV's black background (26 levels) or a blue channel 25 levels
// off beside two equal ones is not (it once was: any channel of ours near
// a boundary sufficed), nor is one level off far from a boundary.
TEST(PovExplain, Float32ColourNeedsOneLevelAtARoundingBoundary) {
  const float tenth[3] = {0.1f, 0.1f, 0.1f};
  const float pov25[3] = {25 / 255.f, 25 / 255.f, 25 / 255.f};
  const float black[3] = {0, 0, 0};
  const float blue_off[3] = {26 / 255.f, 26 / 255.f, 51 / 255.f};
  EXPECT_NE(float32_colour_cause(tenth, pov25, 255).find("float32 colour"), std::string::npos);
  EXPECT_EQ(float32_colour_cause(tenth, black, 255), "");
  EXPECT_EQ(float32_colour_cause(tenth, blue_off, 255), "");
  const float fifth[3] = {0.2f, 0.2f, 0.2f};  // 51.0000007 levels: no boundary near
  const float pov52[3] = {52 / 255.f, 52 / 255.f, 52 / 255.f};
  EXPECT_EQ(float32_colour_cause(fifth, pov52, 255), "");
  EXPECT_EQ(float32_colour_cause(tenth, tenth, 255), "") << "nothing differs";
}

TEST(PovExplain, CornellBoxEdgePixelIsPovsMeshInsideTest) {
  try {
    find_povray();
  } catch (const InputError&) {
    GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  }
  const auto file = std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes" / "corpus" / "cornell-box.json";
  if (!missing_cache_inputs(file).empty()) GTEST_SKIP() << "the corpus cache is empty (ci/fetch-corpus.sh)";
  Scene scene = load_scene(file);
  RenderOptions opt;
  opt.progress = false;
  const Image ours = render(scene, opt);
  const Image pov = render_with_povray(scene).image;
  const ImageComparison c = compare_images(ours, pov, 8);
  bool found = false;
  for (const auto& d : c.differences) found |= d.x == 301 && d.y == 63 && d.levels > 200;
  ASSERT_TRUE(found) << "POV-Ray and we no longer differ at (301, 63): the case is gone";
  // Our tracer with POV's mesh2 test sees what POV-Ray sees there.
  RenderOptions pov_test = opt;
  pov_test.pov_mesh_hit = pov_test.pov_mesh_intersect = true;
  const Color with_pov_test = Tracer(scene, pov_test).pixel(301, 63);
  EXPECT_EQ(quantize(float(with_pov_test.x), 255), quantize(pov.at(301, 63)[0], 255));
  const auto ex = explain_differences(scene, ours, pov, c, opt);
  for (const auto& e : ex) {
    EXPECT_FALSE(e.cause.empty()) << "(" << e.x << ", " << e.y << ") unexplained";
    if (e.x == 301 && e.y == 63) {
      EXPECT_EQ(e.cause.rfind("mesh2 intersection", 0), 0u) << e.cause;
    }
  }
}

// Renders `scene` with us and with POV-Ray: pixel (x, y) must differ (else
// the case is gone and the test says so), every differing pixel must have a
// cause, and (x, y)'s must start with `cause`.
void expect_pixel_differs_and_is_explained_by(const Scene& scene, int x, int y, const std::string& cause) {
  RenderOptions opt;
  opt.progress = false;
  const Image ours = render(scene, opt);
  const Image pov = render_with_povray(scene).image;
  const ImageComparison c = compare_images(ours, pov, 8);
  bool found = false;
  for (const auto& d : c.differences) found |= d.x == x && d.y == y;
  ASSERT_TRUE(found) << "POV-Ray and we no longer differ at (" << x << ", " << y << "): the case is gone";
  for (const auto& e : explain_differences(scene, ours, pov, c, opt)) {
    EXPECT_FALSE(e.cause.empty()) << "(" << e.x << ", " << e.y << ") unexplained";
    if (e.x == x && e.y == y) {
      EXPECT_EQ(e.cause.rfind(cause, 0), 0u) << e.cause;
    }
  }
}

// Random scene 3-179 shrunk (compare --random 200 --seed 3): a reflective,
// nearest-textured, smooth regr01.obj scaled to 5e-4, no lights. Its UVs
// run over hundreds of repeats across a triangle, so two reflections turn a
// smooth normal ~1e-7 off into another texel: pixel (87, 95) is POV's only
// when the normal is interpolated through compute_smooth_triangle's Perp
// computed in float32 step by step (renderer/pov_mesh.cpp, pov_perp).
TEST(PovExplain, RandomScene3_179PixelIsPovsFloat32Perp) {
  try {
    find_povray();
  } catch (const InputError&) {
    GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  }
  const auto file = std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "validation" / "random-3-179.json";
  const std::string text = R"({"adc_bailout": 0.2, "ambient_light": 0.452, "background": 0,
    "camera": {"look_at": [-0.459, 0.482, -0.116], "position": [-4.868, 0.329, 3.785],
               "up": [0.286, 0.949, 0.135], "vfov": 25.292},
    "width": 160, "height": 120, "lights": [], "max_depth": 3,
    "objects": [{"material": {"ambient": 0.22, "color": [0.644, 0.166, 0.563], "diffuse": 0.203, "phong": 0.34,
                              "phong_size": 103.882, "reflection": [0.789, 0.373, 0.722],
                              "texture": {"file": "${cache}/corpus/ladder/drkwood2.jpg", "filter": "nearest"}},
                 "mesh": "${cache}/corpus/assimp-obj/regr01.obj", "rotate": [["z", -2.437]], "scale": 0.000526,
                 "shading": "smooth", "translate": [-0.203, -0.037, -0.711]}]})";
  for (const char* input : {"corpus/ladder/drkwood2.jpg", "corpus/assimp-obj/regr01.obj"})
    if (!std::filesystem::exists(cache_dir() / input)) GTEST_SKIP() << "the corpus cache lacks " << input;
  const Scene scene = parse_scene_json(text, file);
  expect_pixel_differs_and_is_explained_by(scene, 87, 95, "mesh2 hit point");
}

// The spider at 160 x 120: pixel (87, 53) is 1/255 off, with our
// value 1e-4 levels from a rounding boundary; POV's Mesh::UVCoord on its
// double UVs (UV_VECT; only vertices and normals are float32) gives POV's
// value there, rounding the UVs to float32 does not.
TEST(PovExplain, SpiderPixelIsPovsMeshUVOnDoubleUVs) {
  try {
    find_povray();
  } catch (const InputError&) {
    GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  }
  const auto file = std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes" / "corpus" / "spider-textured.json";
  if (!missing_cache_inputs(file).empty()) GTEST_SKIP() << "the corpus cache is empty (ci/fetch-corpus.sh)";
  Scene scene = load_scene(file);
  scene.width = 160;
  scene.height = 120;
  expect_pixel_differs_and_is_explained_by(scene, 87, 53, "mesh2 UV");
}

// A smooth triangle whose three normals differ by 1e-6 (|N1 - N2|^2 =
// 1e-12): POV-Ray's Parse_Mesh2 calls it flat (|N1 - N2|^2 and |N1 - N3|^2
// at most EPSILON = 1e-10) and shades it with its plane normal, tilted 14
// degrees from the given ones, so most of the triangle differs by many
// levels; the equal-normals model, with POV's tolerance, gives POV's pixels.
TEST(PovExplain, NearlyEqualNormalsMakeAFlatTriangle) {
  try {
    find_povray();
  } catch (const InputError&) {
    GTEST_SKIP() << "POV-Ray is not installed (Debian package povray)";
  }
  // Named per process: GoogleTest's random seed is 0 unless shuffling, so it
  // named the same folder for the release and sanitizer suites run at once.
  const auto dir = std::filesystem::temp_directory_path() / ("rayaudit-near-normals-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "tri.obj");
    obj << "v -1 -1 0\nv 1 -1 0\nv 0 1 0.5\nvn 0 0 1\nvn 1e-6 0 1\nvn 0 1e-6 1\nf 1//1 2//2 3//3\n";
  }
  const std::string text = R"({"width": 40, "height": 30,
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "vfov": 45},
    "lights": [{"position": [3, 4, 5]}],
    "objects": [{"mesh": "tri.obj", "shading": "smooth", "material": {"color": [0.8, 0.6, 0.4]}}]})";
  const Scene scene = parse_scene_json(text, dir / "scene.json");
  RenderOptions opt;
  opt.progress = false;
  const Image ours = render(scene, opt);
  const Image pov = render_with_povray(scene).image;
  std::filesystem::remove_all(dir);
  const ImageComparison c = compare_images(ours, pov, 8);
  int many_levels = 0;
  for (const auto& d : c.differences) many_levels += d.levels > 4;
  ASSERT_GT(many_levels, 50) << "POV-Ray no longer shades the triangle flat";
  const auto ex = explain_differences(scene, ours, pov, c, opt);
  for (const auto& e : ex) {
    EXPECT_FALSE(e.cause.empty()) << "(" << e.x << ", " << e.y << ") unexplained";
    if (e.levels > 4) {
      EXPECT_EQ(e.cause.rfind("equal normals", 0), 0u) << e.cause;
    }
  }
}

}  // namespace
}  // namespace ra
