// The BVH over a scene's objects (render.cpp, POV-Ray's automatic bounding;
// scenes of thousands of objects): the same image, bit for bit, as the loop over every
// object, for every method and precision; a repeated mesh is one set.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../registry.h"
#include "../render.h"

namespace ra {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("rayaudit_object_bvh_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

// A small closed mesh (an octahedron) to place several times.
const char* kOctahedron =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

// Many spheres and lone triangles in a jumble (a fixed LCG), some given
// twice at the same place (ties on t, which the lower object must win
// whatever the order), a mesh placed three times (twice the same way),
// reflecting planes (unbounded: outside the object BVH) and two lights.
std::string jumble_scene(const fs::path& dir) {
  std::ofstream(dir / "octa.obj") << kOctahedron;
  std::uint32_t state = 12345;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1u << 24);  // [0, 1)
  };
  auto coord = [&] { return std::to_string(-2 + 4 * next()); };
  std::ostringstream s;
  s << R"({"width": 40, "height": 30, "max_depth": 3,
    "camera": {"position": [0.5, 3, 7], "look_at": [0, 0, 0], "vfov": 50},
    "lights": [{"position": [3, 5, 4]}, {"position": [-4, 2, 3], "color": [0.4, 0.4, 0.6]}],
    "objects": [
      {"plane": {"normal": [0, 1, 0], "offset": -2.5}, "material": {"reflection": 0.3}},
      {"plane": {"normal": [0, 0, 1], "offset": -4}, "material": {"color": [0.3, 0.5, 0.9]}},
      {"mesh": "octa.obj", "scale": 0.6, "material": {"reflection": 0.4, "phong": 0.5}},
      {"mesh": "octa.obj", "translate": [1.5, 0.3, 0.2], "shading": "smooth"},
      {"mesh": "octa.obj", "scale": 0.6, "material": {"reflection": 0.4, "phong": 0.5}})";
  for (int i = 0; i < 60; ++i) {
    const std::string sphere = R"({"sphere": {"center": [)" + coord() + ", " + coord() + ", " + coord() +
                               "], \"radius\": " + std::to_string(0.05 + 0.3 * next()) +
                               R"(}, "material": {"color": [)" + std::to_string(next()) + ", 0.5, 0.5]" +
                               (i % 5 == 0 ? ", \"reflection\": 0.5" : "") + "}}";
    s << ",\n      " << sphere;
    if (i % 7 == 0) s << ",\n      " << sphere;  // the same sphere again
    const std::string a = coord(), b = coord(), c = coord();
    const std::string tri = "{\"triangle\": [[" + a + ", " + b + ", " + c + "], [" + coord() + ", " + b + ", " + c +
                            "], [" + a + ", " + coord() + ", " + c + "]], \"material\": {\"color\": [0.9, " +
                            std::to_string(next()) + ", 0.2]}}";
    s << ",\n      " << tri;
    if (i % 6 == 0) s << ",\n      " << tri;
  }
  s << "]}\n";
  return s.str();
}

// Methods whose hits lie inside the triangle up to rounding (as in
// mesh_render_test's Accel tests: angles and areas widen triangles by an
// absolute tolerance, which every bounding volume rightly drops).
bool exact_inside(const std::string& name) { return name != "angles" && name != "areas"; }

TEST(ObjectBvh, SameBitsAsTheLoopOverObjectsForEveryMethodAndPrecision) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "jumble.json") << jumble_scene(dir);
  const Scene scene = load_scene(dir / "jumble.json");
  ASSERT_GT(scene.objects.size(), 130u);
  std::vector<std::string> spheres;
  for (const Method& m : methods())
    if (m.kind == Kind::sphere) spheres.push_back(std::string(m.name));
  ASSERT_GE(spheres.size(), 4u);
  std::size_t k = 0;
  int nonblack = 0;
  for (const Method& m : methods()) {
    if (m.kind != Kind::triangle || !exact_inside(std::string(m.name))) continue;
    for (bool dbl : {true, false}) {
      RenderOptions o;
      o.progress = false;
      o.triangle_method = std::string(m.name);
      o.sphere_method = spheres[k++ % spheres.size()];
      o.use_double = dbl;
      o.object_bvh = false;
      const Image loop = render(scene, o);
      o.object_bvh = true;
      const Image bvh = render(scene, o);
      EXPECT_EQ(loop.rgb, bvh.rgb) << m.name << " / " << o.sphere_method << (dbl ? " double" : " float");
      // Asking for the nodes and leaves beside those met (the soup's BVH
      // and each mesh's; the objects' BVH never asks) changes no bit.
      o.neighbour_prefetch = RenderOptions::NeighbourPrefetch::always;
      EXPECT_EQ(loop.rgb, render(scene, o).rgb) << m.name << " with neighbour prefetch";
      for (float v : loop.rgb) nonblack += v > 0.05f;
    }
  }
  EXPECT_GT(nonblack, 1000) << "the scene is seen";
  fs::remove_all(dir);
}

// POV-Ray's shadow cache asks about one object alone (the `only` path) and
// runs in POV's order: still the same bits with the object BVH.
TEST(ObjectBvh, SameBitsWithPovRaysShadowCache) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "jumble.json") << jumble_scene(dir);
  const Scene scene = load_scene(dir / "jumble.json");
  RenderOptions o;
  o.progress = false;
  o.pov_shadow_cache = true;
  o.object_bvh = false;
  const Image loop = render(scene, o);
  o.object_bvh = true;
  EXPECT_EQ(loop.rgb, render(scene, o).rgb);
  fs::remove_all(dir);
}

// A mesh placed the same way by several objects is loaded once and the
// objects share it (the tracer prepares each set once); another placement
// is its own set.
TEST(ObjectBvh, AMeshPlacedTheSameWayTwiceIsOneSet) {
  const fs::path dir = temp_dir();
  std::ofstream(dir / "jumble.json") << jumble_scene(dir);
  const Scene scene = load_scene(dir / "jumble.json");
  EXPECT_EQ(scene.objects[2].mesh.get(), scene.objects[4].mesh.get());
  EXPECT_NE(scene.objects[2].mesh.get(), scene.objects[3].mesh.get());
  EXPECT_EQ(scene.objects[3].mesh->shading, Shading::smooth);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ra
