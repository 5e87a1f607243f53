// `rayaudit render` on scenes that are large or extreme rather than
// malformed: many objects, a
// repeated mesh, a 100 MB path, a radiance beyond a float.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "image.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using ra::test::one_line;
using ra::test::run_rayaudit;
using ra::test::slurp;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("rayaudit-render-limits-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}

// Two facing mirrors of reflection 2 at max_depth 256: 2^256 overflows a
// float. An EXR would have held +inf (exit 0): refused, naming the scene
// and the pixel. A PNG clamps it to white, as POV-Ray's float colours do.
TEST(RenderLimitsCli, RadianceBeyondAFloatIsRefusedForExrAndWhiteInPng) {
  const fs::path scene = scratch("mirrors.json");
  std::ofstream(scene) << R"({"width": 4, "height": 4, "max_depth": 256, "adc_bailout": 0,
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
    "objects": [{"plane": {"normal": [0, 0, 1], "offset": -1}, "material": {"reflection": 2, "color": 1}},
                {"plane": {"normal": [0, 0, -1], "offset": -1}, "material": {"reflection": 2, "color": 1}}]})";
  const fs::path exr = scratch("mirrors.exr");
  const auto r = run_rayaudit("render " + scene.string() + " -o " + exr.string());
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind(scene.string() + ": pixel (0, 0) has radiance +inf, beyond a float's range", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(exr));
  const fs::path png = scratch("mirrors.png");
  const auto p = run_rayaudit("render " + scene.string() + " -o " + png.string());
  EXPECT_EQ(p.code, 0) << p.all;
  const ra::Image img = ra::read_image(png);
  ASSERT_EQ(img.width, 4);
  EXPECT_EQ(img.at(0, 0)[0], 1.0f) << "+inf is white";
}

// A 100 MB mesh path: one short line (it was the whole path, 100 MB).
TEST(RenderLimitsCli, AHugePathIsNotQuotedWhole) {
  const fs::path scene = scratch("longpath.json");
  std::ofstream(scene) << R"({"width": 4, "height": 4, "objects": [{"mesh": ")" << std::string(1 << 20, 'a')
                       << R"(.obj"}]})";
  const auto r = run_rayaudit("render " + scene.string() + " -o " + scratch("o.png").string());
  EXPECT_EQ(r.code, 2) << r.err.substr(0, 300);
  EXPECT_TRUE(one_line(r.err)) << r.err.substr(0, 300);
  EXPECT_EQ(r.err, scene.string() +
                       ": /objects/0/mesh: a path of 1048580 bytes, longer than a path can be (4095 bytes)\n");
}

// AddressSanitizer reserves terabytes of address space: tests that limit it
// with prlimit --as cannot run under the asan preset.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// One mesh placed 400 times was loaded and given a BVH 400 times (a
// 69,666-triangle mesh: 3.5 GB). A 20,000-triangle mesh placed 400 times
// (about 1.6 GB as 400 copies) now renders under a 1 GB address-space limit.
TEST(RenderLimitsCli, AMeshPlaced400TimesIsLoadedOnce) {
  if (kSanitized) GTEST_SKIP() << "prlimit --as under ASan";
  const fs::path mesh = scratch("grid.obj");
  {
    std::ofstream out(mesh);
    const int n = 100;  // (n x n) quads, 2 triangles each
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) out << "v " << i * 0.01 << " " << j * 0.01 << " " << (i * j % 7) * 0.001 << "\n";
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
        out << "f " << a << " " << b << " " << d << "\nf " << a << " " << d << " " << c << "\n";
      }
  }
  const fs::path scene = scratch("m400.json");
  {
    std::ofstream out(scene);
    out << R"({"width": 8, "height": 8, "objects": [)";
    for (int i = 0; i < 400; ++i) out << (i ? ", " : "") << R"({"mesh": "grid.obj"})";
    out << "]}\n";
  }
  const fs::path png = scratch("m400.png");
  const auto r = run_rayaudit("render " + scene.string() + " -o " + png.string(), "prlimit --as=1000000000 --");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(png));
}

// 10,000 spheres were intersected by a loop over all of them (15 s at
// 320x240); through the object BVH they are a fraction of a second. Under a
// 20 s CPU limit (a bound against runaway, not a timing), on one thread.
TEST(RenderLimitsCli, TenThousandSpheresAreBoundedByTheObjectBvh) {
  const fs::path scene = scratch("sp10k.json");
  {
    std::ofstream out(scene);
    out << R"({"width": 320, "height": 240, "objects": [)";
    for (int i = 0; i < 10000; ++i)
      out << (i ? ", " : "") << R"({"sphere": {"center": [)" << i * 0.001 << R"(, 0, 0], "radius": 0.001}})";
    out << "]}\n";
  }
  const fs::path png = scratch("sp10k.png");
  const auto r = run_rayaudit("render " + scene.string() + " -o " + png.string() + " --threads 1",
                              "prlimit --cpu=20 --");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(png));
}

// Under an address-space limit of 410-450 MB every image command
// aborted (134), crashed (139) or hung inside dlopen, where threads
// OpenImageIO's libraries start were refused; at 460-520 MB a valid texture
// was "cannot be allocated". Now one line naming the limit, before dlopen.
TEST(RenderLimitsCli, AnAddressSpaceLimitTooLowForTheImageModuleIsOneLine) {
  if (kSanitized) GTEST_SKIP() << "prlimit --as under ASan";
  const std::string src = RAYAUDIT_SOURCE_DIR;
  const fs::path scene = scratch("textured.json");
  std::ofstream(scene) << R"({"width": 8, "height": 8, "objects": [{"mesh": ")" << src
                       << R"(/scenes/meshes/quad.obj", "material": {"texture": ")" << src
                       << R"(/scenes/textures/uv-grid.png"}}]})";
  const fs::path png = scratch("textured.png");
  for (const char* limit : {"300000000", "430000000", "450000000", "520000000"}) {
    const auto r = run_rayaudit("render " + scene.string() + " -o " + png.string(),
                                std::string("timeout -s KILL 60 prlimit --as=") + limit + " --");
    EXPECT_EQ(r.code, 2) << limit << ": " << r.all;
    EXPECT_TRUE(one_line(r.err)) << limit << ": " << r.err;
    EXPECT_EQ(r.err.rfind("rayaudit_image.so: the image module (OpenImageIO) needs about 560 MB of address space "
                          "to load, but only ",
                          0),
              0u)
        << r.err;
    EXPECT_FALSE(fs::exists(png));
  }
  const auto ok = run_rayaudit("render " + scene.string() + " -o " + png.string(), "prlimit --as=700000000 --");
  EXPECT_EQ(ok.code, 0) << ok.all;
}

}  // namespace
