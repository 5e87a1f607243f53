// `rayaudit render` on scenes and sizes that are large or extreme rather
// than malformed: many objects, a repeated mesh, a 100 MB path, a radiance
// beyond a float, a scene smaller than POV-Ray's windows; absurd sizes and
// memory or address-space limits refused up front in one line.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "image.h"
#include "run_rayaudit.h"

namespace fs = std::filesystem;
using namespace ra::test;

namespace {

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
  EXPECT_EQ(r.err,
            scene.string() + ": /objects/0/mesh: a path of 1048580 bytes, longer than a path can be (4095 bytes)\n");
}

// One mesh placed 400 times was loaded and given a BVH 400 times (a
// 69,666-triangle mesh: 3.5 GB). A 20,000-triangle mesh placed 400 times
// (about 1.6 GB as 400 copies) now renders under a 1 GB address-space limit.
TEST(RenderLimitsCli, AMeshPlaced400TimesIsLoadedOnce) {
  RAYAUDIT_SKIP_IF_SANITIZED();
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
  const auto r =
      run_rayaudit("render " + scene.string() + " -o " + png.string() + " --threads 1", "prlimit --cpu=20 --");
  EXPECT_EQ(r.code, 0) << r.all;
  EXPECT_TRUE(fs::exists(png));
}

// Under an address-space limit of 410-450 MB every image command
// aborted (134), crashed (139) or hung inside dlopen, where threads
// OpenImageIO's libraries start were refused; at 460-520 MB a valid texture
// was "cannot be allocated". Now one line naming the limit, before dlopen.
TEST(RenderLimitsCli, AnAddressSpaceLimitTooLowForTheImageModuleIsOneLine) {
  RAYAUDIT_SKIP_IF_SANITIZED();
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

TEST(RenderLimitsCli, AbsurdRenderIsRefusedWithItsSize) {
  const fs::path out = scratch("absurd.png");
  const auto r = run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 --spp 256 -o " +
                              out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "16384x16384 at 256 spp is 68719476736 primary rays, more than the limit of 4294967296 "
            "(16384x16384 at 16 spp): lower --width, --height or --spp\n");
  EXPECT_FALSE(fs::exists(out));
}

// A 1e-5 quad as a bare .obj: POV-Ray's 1e-4 minimum depth drops every
// camera hit, so the image is black; the render says why (it said nothing).
// The same quad at unit size renders without a warning.
TEST(RenderLimitsCli, ASceneSmallerThanPovsWindowsIsWarnedAbout) {
  const fs::path obj = scratch("tiny_quad.obj"), unit = scratch("unit_quad.obj"), out = scratch("tiny.png");
  std::ofstream(obj) << "v 0 0 0\nv 1e-5 0 0\nv 0 1e-5 0\nv 1e-5 1e-5 0\nf 1 2 4 3\n";
  std::ofstream(unit) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n";
  auto r = run_rayaudit("render " + obj.string() + " -o " + out.string() + " --width 8 --height 8");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: " + obj.string() + ": the scene is 1.41e-05 across"), std::string::npos) << r.err;
  r = run_rayaudit("render " + unit.string() + " -o " + out.string() + " --width 8 --height 8");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// A legal 16384 x 16384 texture (a 32 KB PNG: 1-bit grey, all zero, deflated)
// that a process limited to 3 GB cannot hold: one line naming the file, not
// a bare std::bad_alloc.
// A 32 KB 1-bit PNG of 16384 x 16384 peaked at 1.24 GB (a float copy of
// every channel, then 3 floats a texel) before "not enough memory" under
// 4 GB. Textures keep the file's own 8 bits now (256 MB here): it renders
// under 3 GB, and under 700 MB (OIIO's libraries map ~500 MB) it is refused
// from its size before the buffer is allocated, naming the file.
TEST(RenderLimitsCli, Texture16384OneBitLoadsInItsOwnBytesOrIsRefusedUpFront) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const std::string tex = std::string(RAYAUDIT_SOURCE_DIR) + "/cli/testdata/texture-16384-1bit.png";
  const fs::path scene = scratch("bigtex.json");
  std::ofstream(scene) << R"({"objects": [{"mesh": ")" << kScenes << R"(/meshes/quad.obj", "material": {"texture": ")"
                       << tex << "\"}}]}\n";
  const std::string args = "render " + scene.string() + " --width 8 --height 8 -o " + scratch("bigtex.png").string();
  rusage before{};
  ::getrusage(RUSAGE_CHILDREN, &before);
  const auto ok = run_rayaudit(args, "prlimit --as=3000000000 --");
  EXPECT_EQ(ok.code, 0) << ok.all;
  rusage after{};
  ::getrusage(RUSAGE_CHILDREN, &after);
  // Largest child so far: this run, unless an earlier child was larger.
  if (after.ru_maxrss > before.ru_maxrss) {
    EXPECT_LT(after.ru_maxrss, 700L * 1024) << "peak resident KB";
  }
  const auto r = run_rayaudit(args, "prlimit --as=700000000 --");
  if (r.code == 0) GTEST_SKIP() << "OpenImageIO's libraries map less here: 700 MB holds the texture";
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind(tex + ": texture of 16384x16384 needs 256 MB to read, but only ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("not enough memory"), std::string::npos) << r.err;
}

// Under an address-space limit too low for OpenImageIO's libraries (they
// map ~430 MB and start threads as they load), every image command aborted,
// segfaulted or hung at 410-450 MB, or blamed a valid texture up to ~520 MB.
// The module is refused before it is loaded, in one line.
TEST(RenderLimitsCli, ImageModuleUnderALowAddressSpaceLimitIsOneLine) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  for (const char* limit : {"300000000", "410000000", "430000000", "450000000", "500000000"}) {
    const auto r =
        run_rayaudit("render " + kScenes + "/bump-height.json --width 8 --height 8 -o " + scratch("lowas.png").string(),
                     std::string("prlimit --as=") + limit + " --");
    EXPECT_EQ(r.code, 2) << limit << "\n" << r.all;
    EXPECT_TRUE(one_line(r.err)) << limit << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("rayaudit_image.so: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("MB of address space to load"), std::string::npos) << r.err;
  }
}

// A render whose image buffers exceed the memory left is refused before
// the work with its estimate (it died of a bare std::bad_alloc after 37 s).
TEST(RenderLimitsCli, RenderBeyondTheMemoryLimitIsRefusedWithAnEstimate) {
  RAYAUDIT_SKIP_IF_SANITIZED();
  const fs::path out = scratch("huge.png");
  const auto r =
      run_rayaudit("render " + kScenes + "/doc000-pyramid.json --width 16384 --height 16384 -o " + out.string(),
                   "prlimit --as=2000000000 --");
  EXPECT_EQ(r.code, 2) << r.all;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind("render: 16384x16384 needs about 6144 MB for its image buffers, but only ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
