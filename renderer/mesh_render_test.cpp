// Meshes in the tracer without golden images: smooth normals against the
// analytic sphere, texture lookups at known UVs, bump variants that must not
// change a flat surface, culling and the three accelerations changing
// nothing, the MTL -> finish mapping, and mesh placement.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>

#include "shading/bump.h"
#include "accel/bvh.h"
#include "scene/camera.h"
#include "image.h"
#include "methods/areas.h"
#include "registry.h"
#include "render.h"
#include "scene/scene_mesh.h"
#include "shading/texture.h"

namespace ra {
namespace {

std::filesystem::path temp_dir() {
  auto d = std::filesystem::temp_directory_path() / ("rayaudit_mesh_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

void write_text(const std::filesystem::path& p, const std::string& text) { std::ofstream(p) << text; }

// A UV sphere of radius 1 at the origin: `rings` x `segments`, triangles
// wound outward, optionally with exact vn (= the vertex position).
std::string uv_sphere_obj(int rings, int segments, bool with_vn) {
  std::string s;
  char buf[160];
  std::vector<int> index((rings + 1) * segments);
  int n = 0;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      if ((r == 0 || r == rings) && k > 0) {
        index[r * segments + k] = index[r * segments];
        continue;
      }
      const double th = M_PI * r / rings, ph = 2 * M_PI * k / segments;
      const double x = std::sin(th) * std::cos(ph), y = std::cos(th), z = -std::sin(th) * std::sin(ph);
      std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", x, y, z);
      s += buf;
      if (with_vn) {
        std::snprintf(buf, sizeof buf, "vn %.17g %.17g %.17g\n", x, y, z);
        s += buf;
      }
      index[r * segments + k] = ++n;
    }
  auto face = [&](int a, int b, int c) {
    if (with_vn)
      std::snprintf(buf, sizeof buf, "f %d//%d %d//%d %d//%d\n", a, a, b, b, c, c);
    else
      std::snprintf(buf, sizeof buf, "f %d %d %d\n", a, b, c);
    s += buf;
  };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const int a = index[r * segments + k], b = index[r * segments + (k + 1) % segments];
      const int c = index[(r + 1) * segments + k], d = index[(r + 1) * segments + (k + 1) % segments];
      if (r > 0) face(a, c, b);
      if (r < rings - 1) face(b, c, d);
    }
  return s;
}

RenderOptions opts() {
  RenderOptions o;
  o.progress = false;
  o.threads = 2;
  return o;
}

Vec3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return normalize(Vec3d{g(rng), g(rng), g(rng)});
}

double angle(const Vec3d& a, const Vec3d& b) { return std::atan2(length(cross(a, b)), dot(a, b)); }

// ---------------------------------------------------------------- smooth

// With exact vertex normals on a unit sphere, document 002's interpolation
// n = normalize(nA + l2 (nB - nA) + l3 (nC - nA)) = normalize(p) for the hit
// point p = A + l2 (B - A) + l3 (C - A): the analytic sphere's normal in the
// direction of p. Only rounding separates them: a few ulps, bound 1e-12 rad.
TEST(SmoothNormals, ExactVertexNormalsGiveTheRadialDirection) {
  const auto dir = temp_dir();
  write_text(dir / "sphere_vn.obj", uv_sphere_obj(12, 24, true));
  MeshPlacement place;
  place.file = dir / "sphere_vn.obj";
  place.shading = Shading::smooth;
  Scene scene;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = load_placed_mesh(place);
  scene.objects.push_back(o);
  Tracer tr(scene, opts());
  const unsigned seed = 20240501;
  std::mt19937_64 rng(seed);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3d from = random_unit(rng) * 4.0, target = random_unit(rng) * 0.5;
    auto sp = tr.shading_point({from, target - from});
    if (!sp) continue;
    ++hits;
    ASSERT_LT(angle(sp->n, normalize(sp->p)), 1e-12) << "seed " << seed << " ray " << i;
  }
  EXPECT_GT(hits, 1500);
}

// Area-weighted vertex normals (no vn). Bound, for a triangle inscribed in
// the unit sphere with angular circumradius rho (the angle between its face
// normal and each of its vertices):
//  - each vertex normal is a weighted mean of face normals that are all
//    within rho_max of the vertex's radial direction, so it is within rho_max
//    of it (a cone of half-angle < 90 degrees is convex);
//  - the interpolated N' = sum b_i m_i differs from N = sum b_i v_i = p by at
//    most 2 sin(rho_max / 2), and |N| >= cos(rho) (each v_i makes the angle
//    rho with the face normal);
//  - so angle(normalize(N'), p) <= asin(2 sin(rho_max / 2) / cos(rho_max)).
TEST(SmoothNormals, AreaWeightedNormalsStayWithinTheDerivedBound) {
  const auto dir = temp_dir();
  write_text(dir / "sphere.obj", uv_sphere_obj(12, 24, false));
  MeshPlacement place;
  place.file = dir / "sphere.obj";
  place.shading = Shading::smooth;
  Scene scene;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = load_placed_mesh(place);
  scene.objects.push_back(o);
  double rho = 0;
  for (const auto& t : o.mesh->triangles) {
    const Vec3d a = o.mesh->positions[t.v[0]], b = o.mesh->positions[t.v[1]], c = o.mesh->positions[t.v[2]];
    const Vec3d nf = normalize(cross(b - a, c - a));
    for (const Vec3d& v : {a, b, c}) rho = std::max(rho, angle(nf, v));
  }
  const double bound = std::asin(2 * std::sin(rho / 2) / std::cos(rho));
  ASSERT_LT(bound, 0.5);  // 12 x 24: rho ~ 0.19 rad, bound ~ 0.19 rad
  Tracer tr(scene, opts());
  const unsigned seed = 77;
  std::mt19937_64 rng(seed);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3d from = random_unit(rng) * 4.0, target = random_unit(rng) * 0.5;
    auto sp = tr.shading_point({from, target - from});
    if (!sp) continue;
    worst = std::max(worst, angle(sp->n, normalize(sp->p)));
  }
  EXPECT_LE(worst, bound) << "seed " << seed << " rho " << rho;
  // And smooth shading is far closer than flat shading's rho.
  EXPECT_LT(worst, rho);
}

// Area weighting worked by hand. Vertex 0 is shared by
//   T1 = (0,0,0), (1,0,0), (0,1,0): (B-A)x(C-A) = (0,0,1), area 1/2, and
//   T2 = (0,0,0), (0,4,0), (0,0,5): (0,4,0)x(0,0,5) = (20,0,0), area 10,
// so its area-weighted normal is (20,0,1)/sqrt(401), about 2.9 degrees from
// +x; an unweighted mean of the unit face normals would be (1,0,1)/sqrt(2),
// 45 degrees away. The other vertices belong to one triangle each.
TEST(SmoothNormals, VertexNormalsAreWeightedByTriangleArea) {
  auto set = std::make_shared<TriangleSet>();
  set->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 4, 0}, {0, 0, 5}};
  MeshTriangle3 t1, t2;
  t1.v = {0, 1, 2};
  t2.v = {0, 3, 4};
  set->triangles = {t1, t2};
  set->materials.resize(1);
  set->materials[0].ambient = {0, 0, 0};
  set->shading = Shading::smooth;
  const std::vector<Vec3d> vn = area_weighted_vertex_normals(*set);
  ASSERT_EQ(vn.size(), 5u);
  const double r401 = std::sqrt(401.0);
  EXPECT_NEAR(vn[0].x, 20 / r401, 1e-15);
  EXPECT_EQ(vn[0].y, 0);
  EXPECT_NEAR(vn[0].z, 1 / r401, 1e-15);
  EXPECT_EQ(vn[1], (Vec3d{0, 0, 1}));
  EXPECT_EQ(vn[2], (Vec3d{0, 0, 1}));
  EXPECT_EQ(vn[3], (Vec3d{1, 0, 0}));
  EXPECT_EQ(vn[4], (Vec3d{1, 0, 0}));

  // And the renderer uses them for a mesh without vn: at (1/4, 1/4) on T1
  // (b0 = 1/2, b1 = b2 = 1/4) document 002's interpolation gives
  // normalize(m0/2 + (0,0,1)/2), proportional to (20/sqrt(401), 0, 1 + 1/sqrt(401)).
  Scene scene;
  Object o;
  o.kind = Object::Kind::mesh;
  o.mesh = set;
  scene.objects.push_back(o);
  Tracer tr(scene, opts());
  const auto sp = tr.shading_point({{0.25, 0.25, 3}, {0, 0, -1}});
  ASSERT_TRUE(sp);
  const Vec3d want = normalize(Vec3d{20 / r401, 0, 1 + 1 / r401});
  EXPECT_NEAR(sp->n.x, want.x, 1e-12);
  EXPECT_NEAR(sp->n.y, 0, 1e-12);
  EXPECT_NEAR(sp->n.z, want.z, 1e-12);
  EXPECT_GT(angle(sp->n, normalize(Vec3d{1, 0, 1} * (0.5 / std::sqrt(2.0)) + Vec3d{0, 0, 0.5})), 0.1);
}

// -------------------------------------------------------------- textures

Texture numbered(int w, int h) {
  Texture t(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.set(x, y, {double(x), double(y), 0});
  return t;
}

TEST(Texture, NearestSamplesTheTexelUnderTheUv) {
  const Texture t = numbered(4, 2);
  // Texel (x, y) covers u in [x/W, (x+1)/W), v in [1 - (y+1)/H, 1 - y/H).
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const Vec3d c = t.nearest((x + 0.5) / 4, 1 - (y + 0.5) / 2);
      EXPECT_EQ(c, (Vec3d{double(x), double(y), 0}));
    }
}

TEST(Texture, VZeroIsTheBottomRow) {
  const Texture t = numbered(4, 2);
  EXPECT_EQ(t.nearest(0.1, 0.0).y, 1);   // bottom row is image row H-1
  EXPECT_EQ(t.nearest(0.1, 0.99).y, 0);  // top
}

TEST(Texture, NearestRepeatsInBothDirections) {
  const Texture t = numbered(4, 2);
  EXPECT_EQ(t.nearest(1.3, 0.25), t.nearest(0.3, 0.25));
  EXPECT_EQ(t.nearest(-0.1, 0.25).x, 3);
  EXPECT_EQ(t.nearest(0.3, -0.25).y, t.nearest(0.3, 0.75).y);
  EXPECT_EQ(t.nearest(0.3, 2.75), t.nearest(0.3, 0.75));
}

TEST(Texture, BilinearIsExactAtTexelCentresAndAveragesBetween) {
  const Texture t = numbered(4, 2);
  // Centre of texel (1, 0): u = 1.5/4, v = 1 - 0.5/2 (up to POV's EPSILON).
  const Vec3d c = t.bilinear(1.5 / 4, 0.75);
  EXPECT_NEAR(c.x, 1, 1e-8);
  EXPECT_NEAR(c.y, 0, 1e-8);
  // Halfway between the centres of texels 1 and 2 in x.
  EXPECT_NEAR(t.bilinear(2.0 / 4, 0.75).x, 1.5, 1e-8);
}

TEST(Texture, BilinearWrapsAtTheBorders) {
  const Texture t = numbered(4, 2);
  // At u = 0 the lookup sits halfway between texel 0 and the LAST column.
  EXPECT_NEAR(t.bilinear(0.0, 0.75).x, (0 + 3) / 2.0, 1e-8);
  // At v = 0 (the bottom edge) halfway between the bottom row and the top.
  EXPECT_NEAR(t.bilinear(1.5 / 4, 0.0).y, (1 + 0) / 2.0, 1e-8);
}

// The documents' .tga textures, written through OpenImageIO and read back
// by load_texture. 4 x 2, 8 bits, row 0 at the top:
//   R = 20 + 40 x (20, 60, 100, 140), G = 50 + 100 y (50 top, 150 bottom),
//   B = 7.
// Hand-worked lookups (x = u W, y = H (1 - v), POVRAY.md):
//  nearest  (0.1, 0.1): x 0.4, y 1.8 -> texel (0, 1) = (20, 150, 7) (v = 0 is the bottom row)
//           (0.9, 0.9): x 3.6, y 0.2 -> texel (3, 0) = (140, 50, 7)
//           (1.1, -0.9) repeats (0.1, 0.1); (-0.1, 0.9) repeats (0.9, 0.9)
//  bilinear (0.4375, 0.625): x - 0.5 = 1.25, y - 0.5 = 0.25: 1/4 of column 2 and
//           3/4 of column 1, 1/4 of row 1 and 3/4 of row 0:
//           R = 100/4 + 3*60/4 = 70, G = 150/4 + 3*50/4 = 75
//           (0, 0): halfway between columns 0 and 3 and rows 1 and 0 (wrapping):
//           R = (20 + 140)/2 = 80, G = (150 + 50)/2 = 100
//           (1.4375, -0.375) repeats (0.4375, 0.625)
void expect_hand_worked_tga_lookups(const Texture& t) {
  ASSERT_EQ(t.width, 4);
  ASSERT_EQ(t.height, 2);
  auto expect = [](const Vec3d& got, double r, double g, double b, const char* what) {
    EXPECT_NEAR(got.x, r / 255, 1e-6) << what;
    EXPECT_NEAR(got.y, g / 255, 1e-6) << what;
    EXPECT_NEAR(got.z, b / 255, 1e-6) << what;
  };
  expect(t.nearest(0.1, 0.1), 20, 150, 7, "nearest (0.1, 0.1)");
  expect(t.nearest(0.9, 0.9), 140, 50, 7, "nearest (0.9, 0.9)");
  expect(t.nearest(1.1, -0.9), 20, 150, 7, "nearest (1.1, -0.9)");
  expect(t.nearest(-0.1, 0.9), 140, 50, 7, "nearest (-0.1, 0.9)");
  expect(t.bilinear(0.4375, 0.625), 70, 75, 7, "bilinear (0.4375, 0.625)");
  expect(t.bilinear(0.0, 0.0), 80, 100, 7, "bilinear (0, 0)");
  expect(t.bilinear(1.4375, -0.375), 70, 75, 7, "bilinear (1.4375, -0.375)");
}

unsigned char tga_level(int x, int y, int c) { return c == 0 ? 20 + 40 * x : c == 1 ? 50 + 100 * y : 7; }

TEST(Texture, TgaWrittenByOiioSamplesTheHandWorkedTexels) {
  const auto file = temp_dir() / "grid.tga";
  unsigned char px[2][4][3];
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) px[y][x][c] = tga_level(x, y, c);
  auto out = OIIO::ImageOutput::create(file.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  ASSERT_TRUE(out->open(file.string(), OIIO::ImageSpec(4, 2, 3, OIIO::TypeDesc::UINT8))) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px)) << out->geterror();
  ASSERT_TRUE(out->close());
  expect_hand_worked_tga_lookups(load_texture(file));
}

// Textures keep an 8- or 16-bit file's own values (a 16384^2 1-bit
// PNG took 1.24 GB as floats). Every level, grey and RGB, must read back bit
// for bit as OpenImageIO's own float conversion of the same file gives it.
TEST(Texture, EightAndSixteenBitTexelsAreOiiosFloatsBitForBit) {
  const auto dir = temp_dir();
  for (const int bits : {8, 16})
    for (const int nch : {1, 2, 3, 4}) {
      const int w = bits == 8 ? 256 : 1024, h = bits == 8 ? 1 : 64;  // every 8-bit level; 65536 16-bit ones
      const auto file = dir / ("levels-" + std::to_string(bits) + "-" + std::to_string(nch) + ".png");
      std::vector<std::uint16_t> v16(std::size_t(w) * h * nch);
      std::vector<std::uint8_t> v8(v16.size());
      for (std::size_t i = 0; i < v16.size(); ++i) {
        const std::size_t px = i / std::size_t(nch), c = i % std::size_t(nch);
        v16[i] = std::uint16_t(px * 1 + c * 7919);  // all levels over the pixels, channels differing
        v8[i] = std::uint8_t(px + c * 51);
      }
      auto out = OIIO::ImageOutput::create(file.string());
      ASSERT_TRUE(out);
      const OIIO::TypeDesc td = bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
      ASSERT_TRUE(out->open(file.string(), OIIO::ImageSpec(w, h, nch, td))) << out->geterror();
      ASSERT_TRUE(out->write_image(td, bits == 8 ? static_cast<const void*>(v8.data()) : v16.data()));
      ASSERT_TRUE(out->close());
      const Texture t = load_texture(file);
      EXPECT_EQ(bits == 8 ? t.u8.size() : t.u16.size(), std::size_t(w) * h * (nch >= 3 ? 3 : 1)) << file;
      EXPECT_TRUE(t.rgb.empty()) << "no float copy";
      std::vector<float> ref(std::size_t(w) * h * nch);
      auto in = OIIO::ImageInput::open(file.string());
      ASSERT_TRUE(in);
      ASSERT_TRUE(in->read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, ref.data()));
      int wrong = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const Vec3d got = t.texel(x, y);
          const float* r = &ref[(std::size_t(y) * w + x) * nch];
          const float want[3] = {r[0], nch >= 3 ? r[1] : r[0], nch >= 3 ? r[2] : r[0]};
          for (int c = 0; c < 3; ++c) wrong += got[c] != double(want[c]);
        }
      EXPECT_EQ(wrong, 0) << file;
    }
}

// The PNM checks (maxval 0, samples above maxval) refuse nothing
// that is valid: comments anywhere, samples equal to the maxval, packed
// lines, and a PFM's negative (little-endian) scale.
TEST(Texture, ValidPnmAndPfmTexturesStillLoad) {
  const auto dir = temp_dir();
  std::ofstream(dir / "a.ppm")
      << "P3\n# made by hand\n2 1 # size\n15\n15 0 7\n# a comment between samples\n0 15 15 # end\n";
  const Texture a = load_texture(dir / "a.ppm");
  EXPECT_EQ(a.texel(0, 0).x, 1.0);
  EXPECT_EQ(a.texel(1, 0).y, 1.0);
  std::ofstream(dir / "b.pgm") << "P2 2 1 65535 65535 0\n";
  EXPECT_NEAR(load_texture(dir / "b.pgm").texel(0, 0).x, 1.0, 1e-4);  // OIIO reads 65535 as 65534/65535
  std::string pfm = "PF\n1 1\n-1.0\n";
  const float px[3] = {0.25f, 0.5f, 2.0f};
  pfm.append(reinterpret_cast<const char*>(px), sizeof px);
  std::ofstream(dir / "c.pfm", std::ios::binary) << pfm;
  EXPECT_EQ(load_texture(dir / "c.pfm").texel(0, 0).z, 2.0);
}

// The same texels in a TGA written byte by byte the way most tools write
// it: uncompressed true-colour (type 2), BGR, origin at the BOTTOM left
// (descriptor bit 5 clear), so the file holds the bottom row first.
TEST(Texture, BottomUpTgaIsReadUpright) {
  const auto file = temp_dir() / "bottom-up.tga";
  std::string bytes(18, '\0');
  bytes[2] = 2;    // uncompressed true-colour
  bytes[12] = 4;   // width, little-endian
  bytes[14] = 2;   // height
  bytes[16] = 24;  // bits per pixel; bytes[17] = 0: bottom-left origin
  for (int y = 1; y >= 0; --y)
    for (int x = 0; x < 4; ++x)
      for (int c : {2, 1, 0}) bytes += char(tga_level(x, y, c));
  std::ofstream(file, std::ios::binary) << bytes;
  expect_hand_worked_tga_lookups(load_texture(file));
}

TEST(Texture, PigmentOfATexturedMeshIsTheTexelAtItsUv) {
  const auto dir = temp_dir();
  // 2 x 2: top-left red, top-right green, bottom-left blue, bottom-right white.
  Image img(2, 2);
  auto put = [&](int x, int y, float r, float g, float b) {
    float* p = img.at(x, y);
    p[0] = r, p[1] = g, p[2] = b;
  };
  put(0, 0, 1, 0, 0);
  put(1, 0, 0, 1, 0);
  put(0, 1, 0, 0, 1);
  put(1, 1, 1, 1, 1);
  write_image(dir / "quad.png", img);
  write_text(dir / "quad.obj",
             "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  write_text(dir / "quad.json", R"({"lights": [], "ambient_light": 1, "objects": [{"mesh": "quad.obj",
      "material": {"ambient": 1, "diffuse": 0, "texture": {"file": "quad.png", "filter": "nearest"}}}]})");
  Scene scene = load_scene(dir / "quad.json");
  Tracer tr(scene, opts());
  auto at = [&](double x, double y) { return tr.trace({{x, y, 5}, {0, 0, -1}}); };
  EXPECT_EQ(at(-0.5, 0.5), (Color{1, 0, 0}));  // top-left of the quad = top-left texel
  EXPECT_EQ(at(0.5, 0.5), (Color{0, 1, 0}));
  EXPECT_EQ(at(-0.5, -0.5), (Color{0, 0, 1}));  // v = 0 at the bottom
  EXPECT_EQ(at(0.5, -0.5), (Color{1, 1, 1}));
}

// ------------------------------------------------------------------ bump

TEST(Bump, UvBasisFollowsTheUvLayout) {
  auto b = uv_basis({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0}, {1, 0}, {0, 1});
  ASSERT_TRUE(b);
  EXPECT_NEAR(length(b->tu - Vec3d{1, 0, 0}), 0, 1e-15);
  EXPECT_NEAR(length(b->tv - Vec3d{0, 1, 0}), 0, 1e-15);
  // UVs turned: AB carries +v and AC carries -u, so +u runs along -y.
  b = uv_basis({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0}, {0, 1}, {-1, 0});
  ASSERT_TRUE(b);
  EXPECT_NEAR(length(b->tu - Vec3d{0, -1, 0}), 0, 1e-15);
  EXPECT_NEAR(length(b->tv - Vec3d{1, 0, 0}), 0, 1e-15);
  EXPECT_FALSE(uv_basis({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0}, {1, 1}, {2, 2}));
}

// A constant, non-zero height map: its derivatives are exactly 0 (I - I),
// so n += 0 and bump_height returns n unchanged (no renormalisation, which
// could move n by an ulp). That early return is the code path BY DESIGN for
// any flat map; the ramps below exercise the perturbation itself.
TEST(Bump, HeightVariantOnAFlatMapChangesNothing) {
  Texture flat(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) flat.set(x, y, {0.4, 0.5, 0.6});
  const Texture d = height_derivatives(flat);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ASSERT_EQ(d.texel(x, y), (Vec3d{0, 0, 0})) << x << ", " << y;
  const UvBasis basis{{1, 0, 0}, {0, 1, 0}};
  const Vec3d n = normalize(Vec3d{0.1, -0.2, 1});
  for (double u : {0.0, 0.3, 0.999})
    for (auto f : {TextureFilter::nearest, TextureFilter::bilinear})
      EXPECT_EQ(bump_height(n, d, f, 10.0, u, 0.7, basis), n);
}

// Document 002's variant 2 on 8-bit ramps, worked by hand. An x ramp of
// levels 20 + 30 x: dx = I(x) - I(x+1) = -30/255 inside the image (the
// last column wraps: 230 - 20 = +210), dy = 0. With n = (0,1,0) on a floor
// whose +u is +x and +v is -z (so image +y, = -v, is +z), strength 2:
//   n' = normalize(n + 2 (dx Tu - dy Tv)) = normalize(-60/255, 1, 0).
// A y ramp of levels 20 + 30 y (brighter towards the BOTTOM, image +y):
// dy = -30/255, dx = 0: n' = normalize(n - 2 dy Tv) = normalize(0, 1, -60/255),
// i.e. tilted towards image -y (= +v = -z), away from the high side.
TEST(Bump, HeightVariantOnRampsGivesTheHandWorkedNormal) {
  Texture xr(8, 4), yr(4, 8);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) xr.set(x, y, Vec3d{1, 1, 1} * float((20 + 30 * x) / 255.0));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 4; ++x) yr.set(x, y, Vec3d{1, 1, 1} * float((20 + 30 * y) / 255.0));
  const UvBasis basis{{1, 0, 0}, {0, 0, -1}};
  const Vec3d n{0, 1, 0};
  const double k = 60.0 / 255, len = std::sqrt(1 + k * k);
  for (auto f : {TextureFilter::nearest, TextureFilter::bilinear}) {
    // x = 2.5 of 8 (inside: bilinear mixes columns 2 and 3, both -30/255).
    const Vec3d a = bump_height(n, height_derivatives(xr), f, 2.0, 2.5 / 8, 0.4, basis);
    EXPECT_NEAR(a.x, -k / len, 1e-7);
    EXPECT_NEAR(a.y, 1 / len, 1e-7);
    EXPECT_NEAR(a.z, 0, 1e-15);
    // y = 2.5 of 8: v = 1 - 2.5/8.
    const Vec3d b = bump_height(n, height_derivatives(yr), f, 2.0, 0.6, 1 - 2.5 / 8, basis);
    EXPECT_NEAR(b.x, 0, 1e-15);
    EXPECT_NEAR(b.y, 1 / len, 1e-7);
    EXPECT_NEAR(b.z, -k / len, 1e-7);
  }
  // The wrapped last column: dx = +210/255, so the tilt reverses.
  const Vec3d w = bump_height(n, height_derivatives(xr), TextureFilter::nearest, 1.0, 7.5 / 8, 0.4, basis);
  const double kw = 210.0 / 255;
  EXPECT_NEAR(w.x, kw / std::sqrt(1 + kw * kw), 1e-7);
}

TEST(Bump, HeightVariantTiltsAwayFromTheHighSide) {
  // Brighter (higher) to the right: the surface rises along +u, so the normal
  // tilts towards -u.
  Texture ramp(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ramp.set(x, y, Vec3d{1, 1, 1} * (x / 8.0));
  const Texture d = height_derivatives(ramp);
  const UvBasis basis{{1, 0, 0}, {0, 1, 0}};
  const Vec3d n = bump_height({0, 0, 1}, d, TextureFilter::nearest, 1.0, 0.4, 0.5, basis);
  EXPECT_LT(n.x, 0);
  EXPECT_NEAR(n.y, 0, 1e-15);
}

// Variant 1 with the texels an 8-bit PNG really holds: "flat" (128, 128, 255)
// is d = (1/255, 1/255, 1), not (0, 0, 1). With n = (0,1,0), Tu = +x,
// Tv = -z, strength 1: n' = normalize((1/255, 0, -1/255) + (0, 1, 0))
// = (1, 255, -1)/sqrt(65027); (127, 127, 255) gives (-1, 255, 1)/sqrt(65027);
// (255, 128, 128), a normal along +u: normalize(Tu + Tv/255 + n/255)
// = (255, 1, -1)/sqrt(65027); strength 2 on (128, 128, 255):
// (2, 255, -2)/sqrt(65033).
TEST(Bump, NormalMapWithEightBitTexelsGivesTheHandWorkedNormal) {
  Image img(3, 1);
  const int texels[3][3] = {{128, 128, 255}, {127, 127, 255}, {255, 128, 128}};
  for (int x = 0; x < 3; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 0)[c] = float(texels[x][c] / 255.0);
  const auto file = temp_dir() / "normals8.png";
  write_image(file, img);
  const Texture map = load_texture(file);
  ASSERT_NEAR(map.texel(0, 0).x * 255, 128, 1e-4);  // the 8-bit level survived
  const UvBasis basis{{1, 0, 0}, {0, 0, -1}};
  const Vec3d n{0, 1, 0};
  auto expect = [&](int texel, double strength, Vec3d want) {
    want = normalize(want);
    const Vec3d got = bump_normal_map(n, map, TextureFilter::nearest, strength, (texel + 0.5) / 3, 0.5, basis);
    // The texels are floats: |c - l/255| <= 2^-25 (half an ulp of 0.5), so each
    // component of d is off by <= 2^-24 ~ 6e-8, times the strength.
    EXPECT_NEAR(length(got - want), 0, 3e-7) << "texel " << texel << " strength " << strength;
  };
  expect(0, 1.0, {1, 255, -1});
  expect(1, 1.0, {-1, 255, 1});
  expect(2, 1.0, {255, 1, -1});
  expect(0, 2.0, {2, 255, -2});
  // Not "nothing": the 8-bit flat texel tilts n by atan(sqrt(2)/255).
  const Vec3d flat = bump_normal_map(n, map, TextureFilter::nearest, 1.0, 0.5 / 3, 0.5, basis);
  EXPECT_NEAR(angle(flat, n), std::atan(std::sqrt(2.0) / 255), 2e-7);
}

// POV's bump_map on a grey map: the three taps are equal, the triangle
// (0,h,0), (-1,h,1), (1,h,1) is level and its normal is +Y of the frame = n.
TEST(Bump, PovOnAFlatMapChangesNothing) {
  Texture grey(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) grey.set(x, y, {0.3, 0.3, 0.3});
  const Vec3d m = normalize(Vec3d{0.3, 0.8, 0.2});
  const Vec3d p = bump_pov(m, grey, TextureFilter::bilinear, 0.5, 0.3, 0.6);
  EXPECT_NEAR(length(p - m), 0, 1e-15);
}

// Whole renders of a lit quad in z = 0 facing the camera (+u = +x, +v = +y),
// ambient 0, diffuse 1, white, the light straight above the traced point so
// that the pixel is exactly N'.L = N'.z:
//  - no bump, and a constant non-zero height map (levels 90, 128, 166:
//    derivatives exactly 0): 1, and the two images are bit-identical;
//  - an 8-bit x ramp, levels 20 + 30 x, strength 2, nearest: at texel 2,
//    dx = -30/255, so N' = normalize(-60/255, 0, 1) and the pixel is
//    1/sqrt(1 + (60/255)^2) = 255/sqrt(68625) (hand: 0.97341...).
TEST(Bump, FlatHeightMapRendersTheSameImageAndARampTheHandWorkedShade) {
  const auto dir = temp_dir();
  Image flat(4, 4), ramp(8, 2);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) flat.at(x, y)[c] = float((90 + 38 * c) / 255.0);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) ramp.at(x, y)[c] = float((20 + 30 * x) / 255.0);
  write_image(dir / "flat.png", flat);
  write_image(dir / "ramp.png", ramp);
  write_text(dir / "q.obj",
             "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  // u = 2.5/8 -> x = -0.375; v = 0.25 -> y = -0.5.
  const std::string head = R"({"width": 32, "height": 24, "lights": [{"position": [-0.375, -0.5, 10]}],
      "camera": {"position": [0, 0, 6]},
      "objects": [{"mesh": "q.obj", "material": {"ambient": 0, "diffuse": 1)";
  write_text(dir / "plain.json", head + "}}]}");
  write_text(dir / "flat.json", head + R"(, "bump": {"file": "flat.png", "strength": 50}}}]})");
  write_text(dir / "ramp.json", head + R"(, "bump": {"file": "ramp.png", "strength": 2, "filter": "nearest"}}}]})");
  const Ray<double> ray{{-0.375, -0.5, 5}, {0, 0, -1}};
  const Scene plain = load_scene(dir / "plain.json"), flat_s = load_scene(dir / "flat.json"),
              ramp_s = load_scene(dir / "ramp.json");
  EXPECT_NEAR(Tracer(plain, opts()).trace(ray).x, 1.0, 1e-12);
  EXPECT_NEAR(Tracer(flat_s, opts()).trace(ray).x, 1.0, 1e-12);
  EXPECT_EQ(render(plain, opts()).rgb, render(flat_s, opts()).rgb);
  const Color c = Tracer(ramp_s, opts()).trace(ray);
  EXPECT_NEAR(c.x, 255 / std::sqrt(68625.0), 1e-7);
  EXPECT_EQ(c.x, c.y);
  EXPECT_NE(render(plain, opts()).rgb, render(ramp_s, opts()).rgb);
}

// ------------------------------------------------- culling, accelerations

Scene accel_scene(const std::filesystem::path& dir) {
  write_text(dir / "ball.obj", uv_sphere_obj(16, 32, false));
  write_text(dir / "accel.json", R"({"width": 48, "height": 36,
      "camera": {"position": [0.3, 1.5, 5], "look_at": [0, 0.2, 0], "vfov": 50},
      "lights": [{"position": [3, 5, 4]}],
      "objects": [
        {"plane": {"normal": [0, 1, 0], "offset": -1}, "material": {"reflection": 0.3}},
        {"mesh": "ball.obj", "shading": "smooth", "translate": [-0.6, 0, 0], "material": {"phong": 0.5, "reflection": 0.2}},
        {"mesh": "ball.obj", "translate": [1.2, 0, -0.5], "scale": 0.7, "rotate": [["y", 0.3]]},
        {"sphere": {"center": [0.3, -0.6, 1.2], "radius": 0.4}}
      ]})");
  return load_scene(dir / "accel.json");
}

// Methods whose hits lie inside the triangle up to rounding; the document
// variants that widen triangles by an absolute tolerance (angles, areas)
// find hits outside any bounding volume, which the accelerations rightly
// drop (see scenes/README.md).
bool exact_inside(const std::string& name) { return name != "angles" && name != "areas"; }

TEST(Accel, NoneSphereAndBvhGiveBitIdenticalImages) {
  const Scene scene = accel_scene(temp_dir());
  for (const Method& m : methods()) {
    if (m.kind != Kind::triangle || !exact_inside(m.name)) continue;
    for (bool dbl : {true, false}) {
      RenderOptions o = opts();
      o.triangle_method = m.name;
      o.use_double = dbl;
      o.accel = Accel::none;
      const Image none = render(scene, o);
      o.accel = Accel::sphere;
      const Image sphere = render(scene, o);
      o.accel = Accel::bvh;
      const Image bvh = render(scene, o);
      o.simd = false;  // the baseline SSE2 paths (AVX2 ones above, where the CPU has it)
      const Image bvh_sse2 = render(scene, o);
      EXPECT_EQ(none.rgb, sphere.rgb) << m.name << (dbl ? " double" : " float");
      EXPECT_EQ(none.rgb, bvh.rgb) << m.name << (dbl ? " double" : " float");
      EXPECT_EQ(none.rgb, bvh_sse2.rgb) << m.name << (dbl ? " double" : " float");
    }
  }
}

// Far from the origin a float kernel answers for the ray rounded to float
// (its origin moves by up to 2^-24 of 1e6, 0.06 here), so its hits can lie
// outside the mesh's exact bounding sphere: the sphere test is widened as
// the BVH's boxes are, and the three accelerations agree (they lost 182
// pixels at 1e6 before).
TEST(Accel, FarFromTheOriginFloatSphereTestKeepsEveryHit) {
  const auto dir = temp_dir();
  write_text(dir / "ball.obj", uv_sphere_obj(8, 16, false));
  write_text(dir / "far.json", R"({"width": 96, "height": 72,
      "camera": {"position": [1e6, 1e6, 1000003], "look_at": [1e6, 1e6, 1e6], "vfov": 45},
      "lights": [{"position": [999997, 1000004, 1000005]}],
      "objects": [{"mesh": "ball.obj", "translate": [1e6, 1e6, 1e6]}]})");
  const Scene scene = load_scene(dir / "far.json");
  RenderOptions o = opts();
  o.triangle_method = "moller";
  o.use_double = false;
  o.accel = Accel::none;
  const Image none = render(scene, o);
  o.accel = Accel::sphere;
  EXPECT_EQ(none.rgb, render(scene, o).rgb);
  o.accel = Accel::bvh;
  EXPECT_EQ(none.rgb, render(scene, o).rgb);
  int lit = 0;
  for (float v : none.rgb) lit += v > 0.2f;
  EXPECT_GT(lit, 300) << "the ball is in view";
}

// Document 002: on a closed mesh a ray from outside meets a front face
// first, so skipping back faces changes no camera hit. Secondary rays are
// not culled: near a smooth mesh's shading terminator a shadow ray can run
// into the mesh (its shading normal faces the light, its geometric normal
// away), and culled back faces let it through, a lit seam
// (42 pixels up to 143 levels). So the whole image is the same, flat and
// smooth.
TEST(Accel, CullingChangesNothingOnClosedMeshesSeenFromOutside) {
  const auto dir = temp_dir();
  write_text(dir / "ball.obj", uv_sphere_obj(16, 32, false));
  for (const char* shading : {"flat", "smooth"}) {
    write_text(dir / "closed.json", std::string(R"({"width": 48, "height": 36, "lights": [{"position": [3, 5, 4]}],
        "objects": [{"mesh": "ball.obj", "shading": ")") +
                                        shading + R"("},
                    {"mesh": "ball.obj", "translate": [1.8, 0.5, -1], "shading": ")" +
                                        shading + R"("}]})");
    const Scene scene = load_scene(dir / "closed.json");
    for (Accel a : {Accel::none, Accel::sphere, Accel::bvh}) {
      RenderOptions o = opts();
      o.accel = a;
      o.cull = false;
      const Tracer plain(scene, o);
      o.cull = true;
      const Tracer culled(scene, o);
      const Camera cam(scene.camera, scene.width, scene.height);
      for (int j = 0; j < scene.height; ++j) {
        for (int i = 0; i < scene.width; ++i) {
          const auto r = cam.ray(i + 0.5, j + 0.5);
          const auto h1 = plain.intersect(r), h2 = culled.intersect(r);
          ASSERT_EQ(h1.has_value(), h2.has_value()) << i << "," << j;
          if (h1) {
            EXPECT_TRUE(h1->t == h2->t && h1->object == h2->object && h1->prim == h2->prim);
          }
        }
      }
      EXPECT_EQ(plain.render().rgb, culled.render().rgb) << accel_name(a) << " " << shading;
    }
  }
}

// The closedness test behind --cull, on sets whose answer is known by
// construction: the uv sphere above is closed and outward (its faces are
// written counter-clockwise seen from outside); the same with every face
// reversed faces inward; an open quad and document 004's cube (6 of its 12
// listed faces wind inward, e.g. `f 5 8 7` against `f 1 4 3`) are not safe.
TEST(Cull, OnlyClosedOutwardMeshesAreCulled) {
  const auto dir = temp_dir();
  auto load = [&](const std::string& name, const std::string& text) {
    write_text(dir / name, text);
    MeshPlacement place;
    place.file = dir / name;
    return load_placed_mesh(place);
  };
  const auto ball = load("ball.obj", uv_sphere_obj(8, 12, false));
  EXPECT_EQ(cull_unsafe_reason(*ball), "");
  TriangleSet inverted = *ball;
  for (auto& t : inverted.triangles) std::swap(t.v[1], t.v[2]);
  EXPECT_NE(cull_unsafe_reason(inverted).find("inward"), std::string::npos);
  const auto quad = load("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  EXPECT_NE(cull_unsafe_reason(*quad).find("not closed"), std::string::npos);
  MeshPlacement cube;
  cube.file = std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes/meshes/cube.obj";
  EXPECT_NE(cull_unsafe_reason(*load_placed_mesh(cube)).find("same direction"), std::string::npos);
  // Welding by position: the same ball with a vertex per face corner.
  TriangleSet unshared = *ball;
  unshared.positions.clear();
  for (auto& t : unshared.triangles)
    for (int& v : t.v) {
      unshared.positions.push_back(ball->positions[v]);
      v = int(unshared.positions.size()) - 1;
    }
  EXPECT_EQ(cull_unsafe_reason(unshared), "");
}

// --cull really skips back faces of a closed mesh (a ray from inside the
// ball sees only back faces) and is not applied to an open one (the same ray
// seeing the back of an open mesh, a single quad, still hits it).
TEST(Cull, SkipsBackFacesOfClosedMeshesOnly) {
  const auto dir = temp_dir();
  write_text(dir / "ball.obj", uv_sphere_obj(8, 12, false));
  write_text(dir / "open.obj", "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nf 1 4 3 2\n");
  write_text(dir / "s.json", R"({"objects": [{"mesh": "ball.obj"}, {"mesh": "open.obj", "translate": [10, 0, 0]}]})");
  const Scene scene = load_scene(dir / "s.json");
  RenderOptions o = opts();
  for (bool cull : {false, true}) {
    o.cull = cull;
    const Tracer tr(scene, o);
    const auto inside_ball = tr.intersect(Ray<double>{{0, 0, 0}, {0.1, 0.2, 1}});
    EXPECT_EQ(inside_ball.has_value(), !cull);
    // The open quad at z = -1 faces -z: seen from z = 0 it is a back face,
    // but the mesh is open, so culling leaves it alone.
    EXPECT_TRUE(tr.intersect(Ray<double>{{10, 0, 0}, {0, 0, -1}}).has_value()) << cull;
  }
}

// Every method beside Moller-Trumbore on document 004's cube: rendered with every triangle
// method in both precisions, an image may differ from Moller-Trumbore's in
// double (as 8-bit PNGs) only at pixels whose centre ray passes within half a pixel's
// footprint of a triangle edge (the 12 cube edges or the 6 face diagonals).
// Away from edges every method agrees on which face is hit and where; at
// edges the methods' own tolerances (areas' epsilon3, angles' MINUS_ZERO) and
// strict or inclusive bounds decide differently which of two faces, or
// whether the cube, is hit. The one exception is areas in float, whose
// Heron NaN bug also fires away from the edges (checked below case by case).
// The distance is measured from the geometry, independently of any method.
std::optional<SceneHit> tracer_hit(const Scene& scene, const RenderOptions& o, const Ray<double>& r) {
  return Tracer(scene, o).intersect(r);
}

TEST(Doc004Cube, EveryMethodDiffersFromMollerOnlyAlongTriangleEdges) {
  const Scene scene = load_scene(std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes/doc004-cube.json");
  ASSERT_EQ(scene.objects.size(), 1u);
  const TriangleSet& cube = *scene.objects[0].mesh;
  ASSERT_EQ(cube.triangles.size(), 12u);
  const Camera cam(scene.camera, scene.width, scene.height);
  // Half a pixel at the cube's distance from the camera.
  const double half_pixel = 0.5 * length(scene.camera.look_at - scene.camera.position) * 2 *
                            std::tan(scene.camera.vfov * M_PI / 360) / scene.height;
  auto distance_to_edges = [&](const Ray<double>& r) {
    const Vec3d d = normalize(r.d);
    double best = 1e300;
    for (const auto& t : cube.triangles)
      for (int e = 0; e < 3; ++e) {
        const Vec3d p = cube.positions[t.v[e]], q = cube.positions[t.v[(e + 1) % 3]];
        for (int s = 0; s <= 2000; ++s) {
          const Vec3d x = p + (q - p) * (s / 2000.0);
          best = std::min(best, length(cross(x - r.o, d)));
        }
      }
    return best;
  };
  // The images as written to an 8-bit PNG (float-precision hit points move
  // the shading by far less than a level).
  auto to8 = [](float x) { return int(std::floor(std::clamp(x, 0.f, 1.f) * 255 + 0.5f)); };
  RenderOptions o = opts();
  o.triangle_method = "moller";
  const Image ref = render(scene, o);
  int differing_total = 0;
  for (const Method& m : methods()) {
    if (m.kind != Kind::triangle) continue;
    for (bool dbl : {true, false}) {
      o.triangle_method = m.name;
      o.use_double = dbl;
      const Image img = render(scene, o);
      for (int j = 0; j < img.height; ++j)
        for (int i = 0; i < img.width; ++i) {
          const float *a = img.at(i, j), *b = ref.at(i, j);
          if (to8(a[0]) == to8(b[0]) && to8(a[1]) == to8(b[1]) && to8(a[2]) == to8(b[2])) continue;
          ++differing_total;
          const Ray<double> ray = cam.ray(i + 0.5, j + 0.5);
          if (distance_to_edges(ray) <= half_pixel) continue;
          // Away from the edges only areas in float may differ, through the
          // listing's Heron bug (areas.h): a plane crossing far outside a
          // triangle accepted because a sub-area is NaN; either the camera
          // ray takes such a false hit, or a shadow ray does (darker pixel).
          ASSERT_TRUE(m.name == "areas" && !dbl)
              << m.name << (dbl ? " double" : " float") << " differs away from the edges at pixel " << i << "," << j;
          const auto h = tracer_hit(scene, o, ray), h_ref = tracer_hit(scene, opts(), ray);
          if (h && h_ref && h->prim == h_ref->prim) {
            for (int c = 0; c < 3; ++c) EXPECT_LT(to8(a[c]), to8(b[c])) << "pixel " << i << "," << j;
            continue;
          }
          ASSERT_TRUE(h) << "pixel " << i << "," << j;
          const auto& tri = cube.triangles[h->prim];
          const Vec3<float> A(cube.positions[tri.v[0]]), B(cube.positions[tri.v[1]]), C(cube.positions[tri.v[2]]);
          const Vec3<float> p = Ray<float>(ray).at(float(h->t));
          EXPECT_TRUE(std::isnan(areas::area(p, B, C)) || std::isnan(areas::area(A, p, C)) ||
                      std::isnan(areas::area(A, B, p)))
              << "pixel " << i << "," << j << ": a false hit of areas/float that is not the NaN bug";
        }
    }
  }
  // The document methods with tolerances do differ somewhere (else this
  // test would check nothing).
  EXPECT_GT(differing_total, 0);
}

// ------------------------------------------------------ MTL and placement

TEST(MtlMapping, PhongTermsMapOntoPovFinish) {
  MtlMaterial m;
  m.name = "doc004";
  m.Ka = {0.3, 0.4, 0.5};
  m.Kd = {0.3775, 0.3775, 0.5775};
  m.Ks = {0.9, 0.6, 0.3};
  m.Ns = 10.6;
  const Material out = material_from_mtl(m);
  EXPECT_EQ(out.color, m.Kd);
  EXPECT_EQ(out.diffuse, 1.0);
  // C * ambient = Kd * Ka / Kd = Ka.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.color[c] * out.ambient[c], m.Ka[c], 1e-15);
  EXPECT_NEAR(out.phong, 0.6, 1e-15);
  EXPECT_EQ(out.phong_size, 10.6);
  EXPECT_FALSE(out.texture);
  EXPECT_FALSE(out.bump);
}

TEST(MtlMapping, AmbientWithoutDiffuseIsDroppedWithAWarning) {
  MtlMaterial m;
  m.name = "light";
  m.Ka = {20, 20, 20};
  m.Kd = {0, 0, 0};
  m.Ka_at = "m.mtl:3: Ka";
  std::vector<std::string> warnings;
  const Material out = material_from_mtl(m, &warnings);
  EXPECT_EQ(out.ambient, (Vec3d{0, 0, 0}));
  // One warning naming the statement and the channels (it was one per channel, without a line).
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("m.mtl:3: Ka of material \"light\": no Kd in channel r, g, b", 0), 0u) << warnings[0];
  m.Kd = {0.5, 0, 0.5};
  warnings.clear();
  material_from_mtl(m, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("no Kd in channel g,"), std::string::npos) << warnings[0];
}

// `vn 0 0 0` has no direction: the face using it takes computed normals, as
// a face without vn (the tracer and the POV-Ray export read the same
// triangles, so they agree); the other face keeps its own.
TEST(MeshNormals, ZeroLengthVnFallsBackToComputedNormals) {
  const auto dir = temp_dir();
  write_text(dir / "z.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 0\n"
             "f 1//1 2//1 3//2\nf 2//1 4//1 3//1\n");
  MeshPlacement place;
  place.file = dir / "z.obj";
  place.shading = Shading::smooth;
  const auto set = load_placed_mesh(place);
  ASSERT_EQ(set->triangles.size(), 2u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(set->triangles[0].n[k], -1);
    EXPECT_EQ(set->triangles[1].n[k], 0);
  }
}

TEST(MtlMapping, MapsBecomeTextureAndHeightBump) {
  const auto dir = temp_dir();
  Image img(2, 2);
  write_image(dir / "t.png", img);
  write_text(dir / "m.obj", "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_text(dir / "m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd t.png\nmap_bump -bm 3 t.png\n");
  MeshPlacement place;
  place.file = dir / "m.obj";
  auto set = load_placed_mesh(place);
  ASSERT_GE(set->materials.size(), 1u);
  const Material& m = set->materials[set->triangles[0].material];
  ASSERT_TRUE(m.texture);
  EXPECT_EQ(m.texture->file.filename(), "t.png");
  ASSERT_TRUE(m.bump);
  EXPECT_EQ(m.bump->variant, BumpVariant::height);
  EXPECT_EQ(m.bump->strength, 3.0);
}

TEST(Placement, RotationsInOrderThenScaleThenTranslateAndNormalsRotated) {
  const auto dir = temp_dir();
  write_text(dir / "p.obj", "v 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 5\nf 1//1 2//1 3//1\n");
  MeshPlacement place;
  place.file = dir / "p.obj";
  place.rotations = {{'x', M_PI / 2}, {'y', M_PI / 2}};
  place.scale = 2;
  place.translate = {10, 0, 0};
  auto set = load_placed_mesh(place);
  // (0,1,0): about x by 90 -> (0,0,1); about y by 90 -> (1,0,0); x2, +10.
  EXPECT_NEAR(length(set->positions[1] - Vec3d{12, 0, 0}), 0, 1e-12);
  // vn (0,0,5): about x -> (0,-1,0) normalised; about y -> unchanged.
  EXPECT_NEAR(length(set->normals[0] - Vec3d{0, -1, 0}), 0, 1e-12);
}

TEST(Placement, CachePrefixExpandsToTheCacheDirectory) {
  ::setenv("RAYAUDIT_CACHE", "/some/cache", 1);
  auto p = expand_cache_prefix("${cache}/corpus/ladder/dragon.obj");
  ::unsetenv("RAYAUDIT_CACHE");
  ASSERT_TRUE(p);
  EXPECT_EQ(*p, std::filesystem::path("/some/cache/corpus/ladder/dragon.obj"));
  EXPECT_FALSE(expand_cache_prefix("meshes/cube.obj"));
}

TEST(Placement, BareObjIsAWholeSceneWithCameraAndLight) {
  const auto dir = temp_dir();
  write_text(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Scene s = load_scene(dir / "tri.obj");
  ASSERT_EQ(s.objects.size(), 1u);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].position, s.camera.position);
  Tracer tr(s, opts());
  // The camera looks at the bounding sphere's centre, on the triangle.
  EXPECT_TRUE(tr.intersect({s.camera.position, s.camera.look_at - s.camera.position}));
}

}  // namespace
}  // namespace ra
