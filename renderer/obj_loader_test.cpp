// The OBJ edge cases of shared/CORPUS.md, one test each. Expected counts,
// areas and boxes are worked out by hand in the comments, never by the parser.
#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <random>
#include <cmath>
#include <cstring>
#include <numbers>

#include "mesh.h"
#include "obj_test_util.h"

namespace ra {
namespace {

using test::load_error;
using test::load_text;
using test::TempDir;

bool ends_with(const std::string& s, const std::string& t) {
  return s.size() >= t.size() && s.compare(s.size() - t.size(), t.size(), t) == 0;
}
// True if some warning ends with `t` (warnings start with the full path).
bool has_warning(const Mesh& m, const std::string& t) {
  for (auto& w : m.warnings)
    if (ends_with(w, t)) return true;
  return false;
}

const char* kTri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";  // right triangle, legs 1: area 0.5

TEST(ObjFaces, AllFourFormsGiveTheSameTriangle) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) +
                                  "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                                  "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//1\nf 1/1/1 2/2/1 3/3/1\n");
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_DOUBLE_EQ(m.area(), 4 * 0.5);
  for (auto& t : m.triangles) {
    EXPECT_EQ(t.v[0], 0);
    EXPECT_EQ(t.v[1], 1);
    EXPECT_EQ(t.v[2], 2);
    EXPECT_EQ(t.gnormal, Vec3d(0, 0, 1));  // (1,0,0) x (0,1,0)
  }
  EXPECT_EQ(m.triangles[0].t[0], -1);
  EXPECT_EQ(m.triangles[0].n[0], -1);
  EXPECT_EQ(m.triangles[1].t[2], 2);
  EXPECT_EQ(m.triangles[1].n[2], -1);
  EXPECT_EQ(m.triangles[2].t[1], -1);
  EXPECT_EQ(m.triangles[2].n[1], 0);
  EXPECT_EQ(m.triangles[3].t[1], 1);
  EXPECT_EQ(m.triangles[3].n[1], 0);
  EXPECT_EQ(m.uvs.size(), 3u);
  EXPECT_EQ(m.normals.size(), 1u);
}

TEST(ObjFaces, NegativeIndicesCountBackFromTheFace) {
  // f -3 -2 -1 after 3 vertices = vertices 1 2 3: legs 2, area 2.
  // Then a 4th vertex; `f 1 -3 4`: -3 with 4 defined is vertex 2, so the
  // triangle (0,0,0) (2,0,0) (0,0,1): area |(2,0,0) x (0,0,1)| / 2 = 1.
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 2 0 0\nv 0 2 0\nf -3 -2 -1\nv 0 0 1\nf 1 -3 4\n");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0].v[0], 0);
  EXPECT_EQ(m.triangles[0].v[2], 2);
  EXPECT_EQ(m.triangles[1].v[1], 1);
  EXPECT_EQ(m.triangles[1].v[2], 3);
  EXPECT_DOUBLE_EQ(m.area(), 3.0);
  EXPECT_EQ(m.triangles[1].gnormal, Vec3d(0, -1, 0));  // (2,0,0) x (0,0,1) = (0,-2,0)
}

TEST(ObjFaces, QuadIsAFanOfTwo) {
  // Unit square: 2 triangles (0,1,2), (0,2,3), area 1.
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1].v[0], 0);
  EXPECT_EQ(m.triangles[1].v[1], 2);
  EXPECT_EQ(m.triangles[1].v[2], 3);
  EXPECT_DOUBLE_EQ(m.area(), 1.0);
}

// A "U" (counter-clockwise): (0,0) (3,0) (3,2) (2,2) (2,1) (1,1) (1,2) (0,2).
// Area 3x2 minus the 1x1 notch = 5; 6 triangles. A fan from the first vertex
// would cover 7 (its triangle (0,0) (2,2) (2,1) is inverted and outside).
std::string u_shape(double ox, double oy, bool xz_plane) {
  const double pts[8][2] = {{0, 0}, {3, 0}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::string s;
  char buf[128];
  for (auto& p : pts) {
    if (xz_plane)
      std::snprintf(buf, sizeof buf, "v %.17g 7 %.17g\n", p[0] + ox, p[1] + oy);
    else
      std::snprintf(buf, sizeof buf, "v %.17g %.17g 7\n", p[0] + ox, p[1] + oy);
    s += buf;
  }
  return s + "f 1 2 3 4 5 6 7 8\n";
}

TEST(ObjFaces, ConcavePolygonIsEarClipped) {
  TempDir d;
  const Mesh m = load_text(d, u_shape(0, 0, false));
  ASSERT_EQ(m.triangles.size(), 6u);
  EXPECT_DOUBLE_EQ(m.area(), 5.0);
  for (auto& t : m.triangles) EXPECT_EQ(t.gnormal, Vec3d(0, 0, 1)) << "every piece keeps the winding";
}

TEST(ObjFaces, ConcavePolygonAtLargeCoordinates) {
  // tinyobjloader #295: at 1e8 the projected coordinates lost the polygon.
  // The offsets are integers, so every coordinate and difference is exact.
  TempDir d;
  const Mesh m = load_text(d, u_shape(1e8, -3e8, false));
  ASSERT_EQ(m.triangles.size(), 6u);
  EXPECT_DOUBLE_EQ(m.area(), 5.0);
}

TEST(ObjFaces, ConcavePolygonInAnotherPlane) {
  // (x, y) -> (x, 7, y): winding seen from -y, gnormal (1,0,0) x (0,0,1) = (0,-1,0).
  TempDir d;
  const Mesh m = load_text(d, u_shape(0, 0, true));
  ASSERT_EQ(m.triangles.size(), 6u);
  EXPECT_DOUBLE_EQ(m.area(), 5.0);
  for (auto& t : m.triangles) EXPECT_EQ(t.gnormal, Vec3d(0, -1, 0));
}

TEST(ObjFaces, VeryLongLineFaceOf1000Vertices) {
  // Regular 1000-gon of radius 1: area n/2 sin(2 pi / n) = 500 sin(pi/500).
  const int n = 1000;
  std::string s;
  char buf[96];
  for (int i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "v %.17g %.17g 0\n", std::cos(2 * std::numbers::pi * i / n),
                  std::sin(2 * std::numbers::pi * i / n));
    s += buf;
  }
  s += "f";
  for (int i = 1; i <= n; ++i) {
    s += ' ';
    s += std::to_string(i);
  }
  TempDir d;
  const Mesh m = load_text(d, s + "\n");
  EXPECT_EQ(m.triangles.size(), size_t(n - 2));
  EXPECT_NEAR(m.area(), 500 * std::sin(std::numbers::pi / 500), 1e-12);
}

TEST(ObjFaces, MixedFormsDropTheComponentNotOnEveryCorner) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "vt 0 0\nvn 0 0 1\nf 1/1/1 2//1 3/1/1\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0].t[0], -1);  // corner 2 has no vt
  EXPECT_EQ(m.triangles[0].n[1], 0);   // every corner has vn
  EXPECT_TRUE(has_warning(m, "t.obj:6: face mixes vertex forms (v, v/vt, v//vn, v/vt/vn); texture or normal "
                             "indices not on every corner were dropped (1 face)"));
}

TEST(ObjText, LineContinuationJoinsLinesAndKeepsLineNumbers) {
  // v 1 0 0 is split over lines 2-3, the face over 5-6. Line 7's face names
  // vertex 4 of 3: the error must say line 7.
  const std::string text = "v 0 0 0\nv 1 \\\n0 0\nv 0 1 0\nf 1 2 \\\n3\nf 1 2 4\n";
  TempDir d;
  const Mesh m = load_text(d, text.substr(0, text.rfind("f 1 2 4")));
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_DOUBLE_EQ(m.area(), 0.5);
  EXPECT_EQ(load_error(text), "t.obj:7: vertex index 4 is past the end (3 defined before this face)");
}

TEST(ObjText, ContinuationWithCrlf) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\r\nv 1 \\\r\n 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  EXPECT_EQ(m.positions[1], Vec3d(1, 0, 0));
  EXPECT_EQ(m.triangles.size(), 1u);
}

TEST(ObjText, CrlfLineEnds) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nusemtl red\r\nf 1 2 3\r\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "red");  // no '\r' in the name
  EXPECT_EQ(load_error("v 0 0 0\r\nv 1 0 0\r\nf 1 2 3\r\n"), "t.obj:3: vertex index 3 is past the end (2 defined before this face)");
}

TEST(ObjText, Utf8BomIsSkipped) {
  TempDir d;
  const Mesh m = load_text(d, "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.triangles.size(), 1u);
}

TEST(ObjText, Utf16IsRejected) {
  EXPECT_EQ(load_error(std::string("\xFE\xFF\0v", 4)),
            "t.obj:1: UTF-16 (big-endian BOM) is not supported: convert the file to UTF-8");
  EXPECT_EQ(load_error(std::string("\xFF\xFEv\0", 4)),
            "t.obj:1: UTF-16 (little-endian BOM) is not supported: convert the file to UTF-8");
  EXPECT_EQ(load_error(std::string("v 0 0 0\n\0v", 10)),
            "t.obj:2: NUL byte in a text file (UTF-16 without BOM, or binary?)");
}

TEST(ObjText, NoTrailingNewlineKeepsTheLastLine) {
  // assimp dropped the last line; here the last line is a face, then a usemtl.
  TempDir d;
  EXPECT_EQ(load_text(d, std::string(kTri) + "f 1 2 3").triangles.size(), 1u);
  const Mesh m = load_text(d, std::string(kTri) + "f 1 2 3\nusemtl last");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "last");
}

TEST(ObjText, TabsRunsOfSpacesAndComments) {
  TempDir d;
  const Mesh m = load_text(d,
                           "  # leading comment\n"
                           "v\t0   0\t\t0   # origin\n"
                           "\tv 2 0 0#no space before the comment\n"
                           "v    0 2 0 \t \n"
                           "\n"
                           "f  1\t2   3 # face\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_DOUBLE_EQ(m.area(), 2.0);  // legs 2
  EXPECT_EQ(m.positions[1], Vec3d(2, 0, 0));
}

TEST(ObjText, BackslashInsideANameDoesNotSwallowTheNextLine) {
  // assimp bug: `\` in a name ate the following line. Only `\` right before
  // the line end continues a line.
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "usemtl dir\\name\nf 1 2 3\n");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.materials.at(0).name, "dir\\name");
}

TEST(ObjNumbers, AllForms) {
  // 1e2 = 100, -.5, +3.E-1 = 0.3, .8e-001 = 0.08; 1E2 = 100; 2. = 2.
  TempDir d;
  const Mesh m = load_text(d, "v 1e2 -.5 +3.E-1\nv .8e-001 1E2 2.\nv -0 +0 0.0\n");
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0], Vec3d(100, -0.5, 0.3));
  EXPECT_EQ(m.positions[1], Vec3d(0.08, 100, 2));
  const Bounds3d b = m.bbox();
  EXPECT_EQ(b.min, Vec3d(-0.0, -0.5, 0));
  EXPECT_EQ(b.max, Vec3d(100, 100, 2));
}

// The parser's fast paths (Clinger's, SWAR digit runs, whole-line masks)
// must give exactly std::from_chars's double. Seeded; prints the seed.
TEST(ObjNumbers, FastPathsMatchFromCharsExactly) {
  const unsigned seed = 20261121;
  std::mt19937_64 rnd(seed);
  std::string text;
  std::vector<std::string> tokens;
  char buf[64];
  for (int i = 0; i < 30000; ++i) {
    const double mag = std::pow(10.0, double(int(rnd() % 40)) - 20.0);
    const double x = (double(rnd() % 2000001) / 1e6 - 1.0) * mag;
    switch (rnd() % 4) {
      case 0: std::snprintf(buf, sizeof buf, "%.*f", int(rnd() % 12), x); break;
      case 1: std::snprintf(buf, sizeof buf, "%.*e", int(rnd() % 18), x); break;
      case 2: std::snprintf(buf, sizeof buf, "%.*g", int(1 + rnd() % 17), x); break;
      default: std::snprintf(buf, sizeof buf, "%lld.%0*llu", (long long)(rnd() % 100000000) - 50000000,
                             int(rnd() % 10), (unsigned long long)(rnd() % 10000000000ull)); break;
    }
    tokens.push_back(buf);
  }
  for (size_t i = 0; i + 3 <= tokens.size(); i += 3) text += "v " + tokens[i] + " " + tokens[i + 1] + " " + tokens[i + 2] + "\n";
  const Mesh m = parse_obj(text, "n.obj");
  ASSERT_EQ(m.positions.size(), tokens.size() / 3);
  for (size_t i = 0; i + 3 <= tokens.size(); ++i) {
    double want = 0;
    std::from_chars(tokens[i].data(), tokens[i].data() + tokens[i].size(), want);
    const Vec3d& p = m.positions[i / 3];
    const double got = i % 3 == 0 ? p.x : i % 3 == 1 ? p.y : p.z;
    ASSERT_EQ(0, std::memcmp(&want, &got, sizeof got)) << "seed " << seed << ": '" << tokens[i] << "' gave " << got;
  }
}

TEST(ObjNumbers, NonFiniteAndMalformedAreErrors) {
  EXPECT_EQ(load_error("v 0 0 0\nv nan 0 0\n"), "t.obj:2: non-finite number 'nan' is not accepted");
  EXPECT_EQ(load_error("v -inf 0 0\n"), "t.obj:1: non-finite number '-inf' is not accepted");
  EXPECT_EQ(load_error("v 0 Infinity 0\n"), "t.obj:1: non-finite number 'Infinity' is not accepted");
  EXPECT_EQ(load_error("v 1.#IND 0 0\n"), "t.obj:1: non-finite number '1.#IND' (MSVC notation) is not accepted");
  EXPECT_EQ(load_error("v 1.#INF 0 0\n"), "t.obj:1: non-finite number '1.#INF' (MSVC notation) is not accepted");
  EXPECT_EQ(load_error("v 1 2 3.1+e2\n"), "t.obj:1: malformed number '3.1+e2'");
  EXPECT_EQ(load_error("\nv 1 x 3\n"), "t.obj:2: malformed number 'x'");
  EXPECT_EQ(load_error("v 1 2 0x10\n"), "t.obj:1: malformed number '0x10'");
  EXPECT_EQ(load_error("v 1 2 +-3\n"), "t.obj:1: malformed number '+-3'");
  EXPECT_EQ(load_error("v 1 2 1e400\n"), "t.obj:1: number out of range '1e400'");
  EXPECT_EQ(load_error("v 1 2\n"), "t.obj:1: v needs x y z, x y z w or x y z r g b (2 values given)");
}

TEST(ObjNumbers, AbsurdlyLongNumberIsAnError) {
  const std::string digits(10000, '1');
  EXPECT_EQ(load_error("v 0 0 " + digits + "\n"), "t.obj:1: number too long (10000 characters, at most 200)");
  EXPECT_EQ(load_error("v 0 0 1e-400\n"), "t.obj:1: number out of range '1e-400'");  // underflow too
  const std::string zeros = "0." + std::string(10000, '0') + "1";  // in range, but 10003 characters
  EXPECT_EQ(load_error("v 0 0 " + zeros + "\n"), "t.obj:1: number too long (10003 characters, at most 200)");
}

TEST(ObjVertices, WeightAndColoursAreIgnored) {
  // w is not divided by (only assimp does); the colours are not kept.
  TempDir d;
  const Mesh m = load_text(d, "v 1 2 3 0.5\nv 4 5 6 1 0 0\n");
  EXPECT_EQ(m.positions[0], Vec3d(1, 2, 3));
  EXPECT_EQ(m.positions[1], Vec3d(4, 5, 6));
  EXPECT_EQ(load_error("v 1 2 3 4 5\n"), "t.obj:1: v needs x y z, x y z w or x y z r g b (5 values given)");
  EXPECT_EQ(load_error("v 1 2 3 4 5 6 7 8\n"), "t.obj:1: v: too many values (at most 7)");
}

TEST(ObjVertices, TexCoordsWithOneToThreeValues) {
  TempDir d;
  const Mesh m = load_text(d, "vt 0.5\nvt 0.25 0.75\nvt 0.125 0.5 1\n");
  ASSERT_EQ(m.uvs.size(), 3u);
  EXPECT_EQ(m.uvs[0], (std::array<double, 2>{0.5, 0}));
  EXPECT_EQ(m.uvs[1], (std::array<double, 2>{0.25, 0.75}));
  EXPECT_EQ(m.uvs[2], (std::array<double, 2>{0.125, 0.5}));
  EXPECT_EQ(load_error("vt\n"), "t.obj:1: vt needs 1 to 3 values (none given)");
  EXPECT_EQ(load_error("vt 1 2 3 4\n"), "t.obj:1: vt: too many values (at most 3)");
}

TEST(ObjElements, PointsLinesAndParamVerticesAreCountedAndSkipped) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "vp 0.5\nvp 0.5 0.5\nl 1 2\nl 1 2 3\nl 3 1\np 1\nf 1 2 3\n");
  EXPECT_EQ(m.skipped.vp, 2);
  EXPECT_EQ(m.skipped.l, 3);
  EXPECT_EQ(m.skipped.p, 1);
  EXPECT_EQ(m.triangles.size(), 1u);
}

TEST(ObjGrouping, ObjectsGroupsSmoothingAndMaterials) {
  TempDir d;
  d.write("a.mtl", "newmtl red\nKd 1 0 0\n");
  d.write("b.mtl", "newmtl blue\nKd 0 0 1\n");
  const Mesh m = load_text(d, std::string(kTri) +
                                  "f 1 2 3\n"              // before anything: -1 everywhere
                                  "mtllib a.mtl   b.mtl\n"  // two libraries
                                  "usemtl blue\n"           // usemtl before o
                                  "o first thing\n"
                                  "g left  right\n"         // two names: one group "left right"
                                  "s 1\n"
                                  "f 1 2 3\n"
                                  "g other\nusemtl red\ns off\n"
                                  "f 1 2 3\n"
                                  "g left right\n"
                                  "f 1 2 3\n");
  ASSERT_EQ(m.triangles.size(), 4u);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "red");  // library order, not use order
  EXPECT_EQ(m.materials[1].name, "blue");
  EXPECT_EQ(m.materials[1].Kd, Vec3d(0, 0, 1));
  EXPECT_EQ(m.objects, (std::vector<std::string>{"first thing"}));
  EXPECT_EQ(m.groups, (std::vector<std::string>{"left right", "other"}));
  const auto& t = m.triangles;
  EXPECT_EQ(t[0].material, -1);
  EXPECT_EQ(m.run_of(0).group, -1);
  EXPECT_EQ(m.run_of(0).object, -1);
  EXPECT_EQ(m.run_of(0).smoothing, 0);
  EXPECT_EQ(t[1].material, 1);
  EXPECT_EQ(m.run_of(1).group, 0);
  EXPECT_EQ(m.run_of(1).object, 0);
  EXPECT_EQ(m.run_of(1).smoothing, 1);
  EXPECT_EQ(t[2].material, 0);
  EXPECT_EQ(m.run_of(2).group, 1);
  EXPECT_EQ(m.run_of(2).smoothing, 0);
  EXPECT_EQ(m.run_of(3).group, 0);
  EXPECT_EQ(m.run_of(3).object, 0);
  EXPECT_EQ(m.runs.size(), 4u);  // every triangle changes group, object or smoothing
  EXPECT_TRUE(m.warnings.empty()) << m.warnings[0];
}

TEST(ObjMaterials, MtllibAfterUsemtlAndNameWithSpaces) {
  TempDir d;
  d.write("my lib.mtl", "  newmtl  Material with spaces  \nKd 0.5 0.25 0.125\n");
  const Mesh m = load_text(d, std::string(kTri) + "usemtl Material with spaces\nf 1 2 3\nmtllib my lib.mtl\n");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "Material with spaces");
  EXPECT_EQ(m.materials[0].Kd, Vec3d(0.5, 0.25, 0.125));
  EXPECT_EQ(m.triangles[0].material, 0);
  EXPECT_TRUE(m.warnings.empty());
}

TEST(ObjMaterials, MissingLibraryAndUndefinedMaterialAreWarnings) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "mtllib nowhere.mtl\nusemtl ghost\nf 1 2 3\n");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "ghost");
  EXPECT_EQ(m.materials[0].Kd, Vec3d(0.8, 0.8, 0.8));  // the default
  EXPECT_EQ(m.triangles[0].material, 0);
  EXPECT_TRUE(has_warning(m, "t.obj:4: material library 'nowhere.mtl' not found (its materials get defaults)"));
  EXPECT_TRUE(has_warning(m, "t.obj:5: material 'ghost' is not defined (default material used)"));
}

TEST(ObjMaterials, UnknownStatementIsOneWarningPerKeyword) {
  TempDir d;
  const Mesh m = load_text(d, std::string(kTri) + "curv 0 1 1 2\nfoo\ncurv 0 1 2 3\n");
  ASSERT_EQ(m.warnings.size(), 2u);
  EXPECT_TRUE(has_warning(m, "t.obj:4: unsupported statement 'curv' ignored (2 lines)"));
  EXPECT_TRUE(has_warning(m, "t.obj:5: unsupported statement 'foo' ignored (1 line)"));
}

TEST(ObjErrors, IndexErrorsNameTheFaceLine) {
  const std::string t = kTri;
  EXPECT_EQ(load_error(t + "f 0 1 2\n"), "t.obj:4: vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(load_error(t + "f 0/0/0 1 2\n"), "t.obj:4: vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(load_error(t + "\nf 1 2 4\n"), "t.obj:5: vertex index 4 is past the end (3 defined before this face)");
  // No forward references: vertex 4 is defined only after the face.
  EXPECT_EQ(load_error(t + "f 1 2 4\nv 1 1 1\n"),
            "t.obj:4: vertex index 4 is past the end (3 defined before this face)");
  EXPECT_EQ(load_error(t + "f -4 -2 -1\n"),
            "t.obj:4: relative vertex index -4 reaches before the first one (3 defined before this face)");
  EXPECT_EQ(load_error(t + "vt 0 0\nf 1/2 2/1 3/1\n"),
            "t.obj:5: texture index 2 is past the end (1 defined before this face)");
  EXPECT_EQ(load_error(t + "f 1//1 2//1 3//1\n"), "t.obj:4: normal index 1 is past the end (0 defined before this face)");
  EXPECT_EQ(load_error(t + "f 1 2\n"), "t.obj:4: face with 2 vertices (at least 3 needed)");
  EXPECT_EQ(load_error(t + "f\n"), "t.obj:4: face with 0 vertices (at least 3 needed)");
  EXPECT_EQ(load_error(t + "f 1 2 3x\n"), "t.obj:4: malformed face vertex near 'x'");
  EXPECT_EQ(load_error(t + "f 1/ 2 3\n"), "t.obj:4: malformed texture index ''");
  EXPECT_EQ(load_error(t + "f 1 2 99999999999999999999\n"),
            "t.obj:4: vertex index out of range '99999999999999999999'");
}

TEST(ObjErrors, FileLimits) {
  TempDir d;
  const auto p = d.write("big.obj", std::string(20, '\n'));
  try {
    read_file_bytes(p, 10);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_TRUE(ends_with(e.what(), "big.obj: file is 20 bytes, more than the limit of 10"));
  }
  EXPECT_THROW(load_obj(d.dir / "absent.obj"), InputError);
}

TEST(ObjMeshHelpers, BboxAreaSphere) {
  TempDir d;
  // Triangle (0,0,0) (4,0,0) (0,3,0) plus an unused vertex (0,0,-2):
  // area 6, box (0,0,-2)..(4,3,0), centre (2,1.5,-1); farthest position:
  // all four corners used are at sqrt(4+2.25+1) = sqrt(7.25).
  const Mesh m = load_text(d, "v 0 0 0\nv 4 0 0\nv 0 3 0\nv 0 0 -2\nf 1 2 3\n");
  EXPECT_DOUBLE_EQ(m.area(), 6.0);
  EXPECT_EQ(m.bbox().min, Vec3d(0, 0, -2));
  EXPECT_EQ(m.bbox().max, Vec3d(4, 3, 0));
  const auto s = m.bounding_sphere();
  EXPECT_EQ(s.center, Vec3d(2, 1.5, -1));
  EXPECT_DOUBLE_EQ(s.radius, std::sqrt(7.25));
  EXPECT_TRUE(Mesh{}.bbox().empty());
}

TEST(ObjMeshHelpers, DegenerateTriangleHasZeroNormal) {
  TempDir d;
  const Mesh m = load_text(d, "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 2\n");
  EXPECT_EQ(m.triangles[0].gnormal, Vec3d(0, 0, 0));
  EXPECT_EQ(m.triangles[1].gnormal, Vec3d(0, 0, 0));
}

// A deterministic OBJ exercising state across chunk boundaries: relative
// and absolute indices, polygons, usemtl / g / o / s changes, continuations.
std::string stress_obj(int n) {
  std::string s = "mtllib none.mtl\n";
  unsigned x = 12345;
  auto rnd = [&] { return (x = x * 1103515245u + 12345u) >> 8; };
  long verts = 0;
  for (int i = 0; i < n; ++i) {
    s += "v " + std::to_string(int(rnd() % 100)) + " " + std::to_string(int(rnd() % 100)) + (i % 7 ? " " : " \\\n") +
         std::to_string(int(rnd() % 100)) + "\n";
    s += "vt 0." + std::to_string(rnd() % 100) + " 0.5\nvn 0 0 1\n";
    ++verts;
    if (i % 97 == 5) s += "usemtl m" + std::to_string(rnd() % 5) + "\n";
    if (i % 131 == 7) s += "g g" + std::to_string(rnd() % 4) + " x\n";
    if (i % 151 == 3) s += "o o" + std::to_string(rnd() % 3) + "\n";
    if (i % 61 == 1) s += "s " + std::to_string(rnd() % 3) + "\n";
    if (verts >= 5) {
      const int k = 3 + int(rnd() % 3);
      s += "f";
      for (int j = 0; j < k; ++j) {
        const long idx = 1 + long(rnd() % verts);
        s += (rnd() % 2) ? " " + std::to_string(idx) + "/" + std::to_string(idx) + "/" + std::to_string(idx)
                         : " " + std::to_string(idx - verts - 1) + "/" + std::to_string(idx - verts - 1) + "/" +
                               std::to_string(idx - verts - 1);
      }
      s += "\n";
    }
    if (i % 211 == 9) s += "l 1 2\np 1\nvp 0.5\n";
  }
  return s;
}

void expect_same(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions, b.positions);
  ASSERT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.uvs, b.uvs);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    const auto &s = a.triangles[i], &t = b.triangles[i];
    ASSERT_EQ(0, std::memcmp(s.v, t.v, sizeof s.v)) << i;
    ASSERT_EQ(0, std::memcmp(s.n, t.n, sizeof s.n)) << i;
    ASSERT_EQ(0, std::memcmp(s.t, t.t, sizeof s.t)) << i;
    ASSERT_EQ(s.material, t.material) << i;
    ASSERT_EQ(s.gnormal, t.gnormal) << i;
  }
  std::vector<std::string> an, bn;
  for (auto& m : a.materials) an.push_back(m.name);
  for (auto& m : b.materials) bn.push_back(m.name);
  EXPECT_EQ(an, bn);
  EXPECT_EQ(a.runs, b.runs);
  EXPECT_EQ(a.groups, b.groups);
  EXPECT_EQ(a.objects, b.objects);
  EXPECT_EQ(a.skipped.vp, b.skipped.vp);
  EXPECT_EQ(a.skipped.l, b.skipped.l);
  EXPECT_EQ(a.skipped.p, b.skipped.p);
  EXPECT_EQ(a.warnings, b.warnings);
}

TEST(ObjParallel, IdenticalToSerialForAnyThreadCount) {
  const std::string text = stress_obj(3000);
  const Mesh serial = parse_obj(text, "s.obj");
  ASSERT_GT(serial.triangles.size(), 5000u);
  ASSERT_GT(serial.groups.size(), 1u);
  for (int threads : {2, 3, 7, 64}) {
    ObjOptions opt;
    opt.threads = threads;
    opt.parallel_min_bytes = 0;
    SCOPED_TRACE(threads);
    expect_same(serial, parse_obj(text, "s.obj", opt));
  }
}

TEST(ObjParallel, SameErrorAsSerial) {
  std::string text = stress_obj(2000);
  const size_t at = text.size() * 3 / 4;
  const size_t nl = text.find('\n', at);
  text.insert(nl + 1, "f 1 2 0\n");
  const long line = 2 + long(std::count(text.begin(), text.begin() + long(nl), '\n'));
  ObjOptions opt;
  opt.threads = 4;
  opt.parallel_min_bytes = 0;
  std::string serial, parallel;
  try {
    parse_obj(text, "s.obj");
  } catch (const InputError& e) {
    serial = e.what();
  }
  try {
    parse_obj(text, "s.obj", opt);
  } catch (const InputError& e) {
    parallel = e.what();
  }
  EXPECT_EQ(serial, "s.obj:" + std::to_string(line) + ": vertex index 0 (OBJ indices start at 1)");
  EXPECT_EQ(parallel, serial);
}

}  // namespace
}  // namespace ra
