// MTL statements, texture options, and the fuzzer's findings (regressions).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "mesh.h"
#include "obj_test_util.h"

namespace ra {
namespace {

std::vector<MtlMaterial> parse(const std::string& text, std::vector<std::string>* warn = nullptr) {
  std::vector<std::string> w;
  auto out = parse_mtl(text, "m.mtl", "/base", false, w);
  if (warn) *warn = w;
  return out;
}

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Mtl, AllScalarAndColourStatements) {
  const auto m = parse(
      "# comment\n"
      "  newmtl  shiny red  \n"  // leading spaces, name with a space
      "Ka 0.1 0.2 0.3\nKd 0.5\nKs 1 1 1 # white\nNs 96.078431\nNi 1.45\nd 0.25\nillum 3\n"
      "newmtl second\nTr 0.2\n");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].name, "shiny red");
  EXPECT_EQ(m[0].Ka, Vec3d(0.1, 0.2, 0.3));
  EXPECT_EQ(m[0].Kd, Vec3d(0.5, 0.5, 0.5));  // one value = grey
  EXPECT_EQ(m[0].Ks, Vec3d(1, 1, 1));
  EXPECT_EQ(m[0].Ns, 96.078431);
  EXPECT_EQ(m[0].Ni, 1.45);
  EXPECT_EQ(m[0].d, 0.25);
  EXPECT_EQ(m[0].illum, 3);
  EXPECT_EQ(m[1].name, "second");
  EXPECT_EQ(m[1].d, 1 - 0.2);                // Tr is 1 - d
  EXPECT_EQ(m[1].Kd, Vec3d(0.8, 0.8, 0.8));  // defaults
  EXPECT_EQ(m[1].illum, 2);
}

TEST(Mtl, DWinsOverTrWhateverTheOrder) {
  EXPECT_EQ(parse("newmtl a\nd 0.9\nTr 0.9\n")[0].d, 0.9);
  EXPECT_EQ(parse("newmtl a\nTr 0.9\nd 0.9\n")[0].d, 0.9);
}

TEST(Mtl, TextureOptionsBeforeAFileNameWithSpaces) {
  const auto m = parse(
      "newmtl a\n"
      "map_bump -s 2 2 1 -bm 0.5 my tex.png\n"
      "map_Kd -o 0.5 -clamp on -mm 0 1 -blendu off .\\SpiderTex.jpg\n"
      "map_Ka tex\\sub dir\\a.tga\n"
      "map_Ks /abs/ks.png\n"
      "map_d -imfchan m alpha.png\n");
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].map_bump, "/base/my tex.png");
  EXPECT_EQ(m[0].bump_multiplier, 0.5);
  EXPECT_EQ(m[0].map_Kd, "/base/SpiderTex.jpg");  // backslash converted, ./ removed
  EXPECT_EQ(m[0].map_Ka, "/base/tex/sub dir/a.tga");
  EXPECT_EQ(m[0].map_Ks, "/abs/ks.png");
  EXPECT_EQ(m[0].map_d, "/base/alpha.png");
}

TEST(Mtl, BumpSpellings) {
  EXPECT_EQ(parse("newmtl a\nbump b.png\n")[0].map_bump, "/base/b.png");
  EXPECT_EQ(parse("newmtl a\nmap_Bump -bm 2 b.png\n")[0].bump_multiplier, 2);
  EXPECT_EQ(parse("newmtl a\nmap_bump b.png\n")[0].map_bump, "/base/b.png");
  EXPECT_EQ(parse("newmtl a\nmap_Kd -bm 2 k.png\n")[0].bump_multiplier, 1);  // -bm only for bump
}

TEST(Mtl, WarningsAndErrors) {
  std::vector<std::string> w;
  const auto m = parse("Kd 1 1 1\nnewmtl \nKa spectral x.rfl\nKe 1 1 1\nKe 1 1 1\n", &w);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].name, "");
  EXPECT_EQ(w, (std::vector<std::string>{"m.mtl:1: statement before the first newmtl ignored",
                                         "m.mtl:2: newmtl without a name (material named '')",
                                         "m.mtl:3: Ka spectral/xyz form is not supported (ignored)",
                                         "m.mtl:4: unsupported MTL statement 'Ke' ignored"}));
  EXPECT_EQ(error_of("newmtl a\nKd 1 2\n"), "m.mtl:2: Kd needs 1 or 3 values (2 given)");
  EXPECT_EQ(error_of("newmtl a\n\nNs abc\n"), "m.mtl:3: malformed number 'abc'");
  EXPECT_EQ(error_of("newmtl a\nmap_Kd -s 1 1 1\n"), "m.mtl:2: texture statement without a file name");
}

// A flood of one kind of warning is ten lines and
// a count, and distinct unknown statements are found in linear time.
TEST(Mtl, WarningsOfOneKindAreTenLinesAndACount) {
  std::string text;
  for (int i = 0; i < 12; ++i) text += "Kd 1 1 1\n";
  text += "newmtl a\n";
  for (int i = 0; i < 20000; ++i) text += "zz" + std::to_string(i) + " 1\n";
  std::vector<std::string> w;
  parse(text, &w);
  ASSERT_EQ(w.size(), 22u);
  EXPECT_EQ(w[10], "m.mtl:14: unsupported MTL statement 'zz0' ignored");
  EXPECT_EQ(w[20], "m.mtl:11: 2 more statements before the first newmtl ignored");
  EXPECT_EQ(w[0], "m.mtl:1: statement before the first newmtl ignored");
  EXPECT_EQ(w[21], "m.mtl:24: 19990 more unsupported MTL statements ignored");
}

TEST(Mtl, MissingTextureIsAWarningWithTheLine) {
  test::TempDir d;
  d.write("present.png", "x");
  const auto file = d.write("m.mtl", "newmtl a\nmap_Kd present.png\nmap_Ks absent.png\n");
  std::vector<std::string> w;
  const auto m = load_mtl(file, w);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0], file.string() + ":3: texture 'absent.png' not found (" + (d.dir / "absent.png").string() + ")");
  EXPECT_EQ(m[0].map_Kd, (d.dir / "present.png").string());
}

// Found by ci/fuzz.sh (mtl_fuzz): a huge illum value was cast to int (UB).
TEST(MtlRegression, FuzzIllumHugeValue) {
  std::ifstream f(std::string(RAYAUDIT_SOURCE_DIR) + "/renderer/fuzz/regressions/mtl_illum_huge_value.mtl",
                  std::ios::binary);
  ASSERT_TRUE(f) << "regression input missing";
  std::stringstream ss;
  ss << f.rdbuf();
  EXPECT_EQ(error_of(ss.str()), "m.mtl:3: illum needs an integer 0..1000");
  EXPECT_EQ(error_of("newmtl a\nillum 1e300\n"), "m.mtl:2: illum needs an integer 0..1000");
  EXPECT_EQ(error_of("newmtl a\nKd 1e308 1 1\n"), "m.mtl:2: Kd value 1e+308 has a magnitude above 1e30");
  EXPECT_EQ(error_of("newmtl a\nNs -2e30\n"), "m.mtl:2: Ns value -2e+30 has a magnitude above 1e30");
  EXPECT_EQ(error_of("newmtl a\nillum 2.5\n"), "m.mtl:2: illum needs an integer 0..1000");
}

}  // namespace
}  // namespace ra
