// Judging a comparison: every differing pixel must be explained by position.
#include "pov_tolerance.h"

#include <gtest/gtest.h>

#include <fstream>

#include "errors.h"

namespace ra {
namespace {

ImageComparison with_differences(std::vector<PixelDifference> d, int bits = 8) {
  ImageComparison c;
  c.width = 16;
  c.height = 12;
  c.bits = bits;
  c.differences = std::move(d);
  return c;
}

TEST(PovTolerance, DefaultRequiresIdenticalAt8Bits) {
  const PovTolerance t;
  EXPECT_TRUE(judge(with_differences({}), t).pass);
  EXPECT_FALSE(judge(with_differences({{3, 4, 1}}), t).pass);
}

TEST(PovTolerance, ListedPixelsPassWithTheirCause) {
  PovTolerance t;
  t.pixels = {{3, 4, 200, "shadow cache"}, {5, 5, 1, "gone"}};
  const PovVerdict v = judge(with_differences({{3, 4, 200}}), t);
  EXPECT_TRUE(v.pass);
  ASSERT_EQ(v.lines.size(), 2u);
  EXPECT_NE(v.lines[0].find("explained: shadow cache"), std::string::npos) << v.lines[0];
  EXPECT_NE(v.lines[1].find("no longer differs"), std::string::npos) << v.lines[1];
  EXPECT_FALSE(judge(with_differences({{3, 4, 200}, {0, 0, 1}}), t).pass);
}

TEST(PovTolerance, ListedPixelsApplyOnlyAtTheirSize) {
  PovTolerance t;
  t.width = 320;
  t.height = 240;
  t.pixels = {{3, 4, 200, "shadow cache"}};
  EXPECT_FALSE(judge(with_differences({{3, 4, 200}}), t).pass);
}

// A listed pixel is allowed its own difference, not any difference.
TEST(PovTolerance, ListedPixelsFailBeyondTheirLevels) {
  PovTolerance t;
  t.pixels = {{3, 4, 1, "float32"}, {7, 8, 27, "shadow cache"}};
  EXPECT_TRUE(judge(with_differences({{3, 4, 1}, {7, 8, 27}}), t).pass);
  EXPECT_TRUE(judge(with_differences({{3, 4, 1}, {7, 8, 12}}), t).pass);
  const PovVerdict v = judge(with_differences({{3, 4, 2}, {7, 8, 27}}), t);
  EXPECT_FALSE(v.pass);
  ASSERT_FALSE(v.lines.empty());
  EXPECT_NE(v.lines[0].find("more than the 1 explained"), std::string::npos) << v.lines[0];
  EXPECT_FALSE(judge(with_differences({{3, 4, 1}, {7, 8, 28}}), t).pass);
  EXPECT_FALSE(judge(with_differences({{3, 4, 255}}), t).pass);
}

// At 16 bits a pixel listed with L 8-bit levels may differ by less than
// (L + 1)/255, i.e. 257 (L + 1) 16-bit levels: 514 for L = 1.
TEST(PovTolerance, ListedPixelsAt16BitsGet257TimesLevelsPlusOne) {
  PovTolerance t;
  t.pixels = {{3, 4, 1, "float32"}};
  EXPECT_EQ(allowed_levels_16(1), 514);
  EXPECT_TRUE(judge(with_differences({{3, 4, 514}}, 16), t).pass);
  EXPECT_FALSE(judge(with_differences({{3, 4, 515}}, 16), t).pass);
}

// Unlisted pixels at 16 bits: POV's float32 colours, POVRAY.md's measured
// 2/65535; nothing else passes, and 8 bits stays exact.
TEST(PovTolerance, At16BitsFloat32RoundingIsAllowed) {
  static_assert(kPovFloat32Levels16 == 2);
  const PovTolerance t;
  EXPECT_EQ(t.max_levels_16, 2);
  EXPECT_TRUE(judge(with_differences({{1, 1, 1}, {2, 1, 2}}, 16), t).pass);
  EXPECT_FALSE(judge(with_differences({{1, 1, 3}}, 16), t).pass);
  EXPECT_FALSE(judge(with_differences({{1, 1, 1}}, 8), t).pass);
  PovTolerance exact;
  exact.max_levels_16 = 0;
  EXPECT_FALSE(judge(with_differences({{1, 1, 1}}, 16), exact).pass);
}

TEST(PovTolerance, ReadsTheFileAndRefusesUnknownKeys) {
  const auto dir = std::filesystem::temp_directory_path() / ("rayaudit-tol-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "pov");
  EXPECT_EQ(pov_tolerance_path(dir / "s.json"), dir / "pov" / "s.json");
  std::ofstream(dir / "pov" / "s.json") << R"({"notes": "n", "pixels": [{"x": 1, "y": 2, "levels": 3, "cause": "c"}]})";
  const PovTolerance t = load_pov_tolerance(dir / "pov" / "s.json");
  ASSERT_EQ(t.pixels.size(), 1u);
  EXPECT_EQ(t.pixels[0].x, 1);
  EXPECT_EQ(t.pixels[0].y, 2);
  EXPECT_EQ(t.pixels[0].levels, 3);
  EXPECT_EQ(t.pixels[0].cause, "c");
  EXPECT_EQ(t.max_levels_16, 2);
  auto refused = [&](const std::string& text) {
    std::ofstream(dir / "pov" / "bad.json") << text;
    EXPECT_THROW(load_pov_tolerance(dir / "pov" / "bad.json"), InputError) << text;
  };
  refused(R"({"tolerance": 5})");
  // The old format, levels only in the cause's text: refused, not read as "any".
  refused(R"({"pixels": [{"x": 1, "y": 2, "cause": "27 level(s): shadow cache"}]})");
  refused(R"({"pixels": [{"x": 1, "y": 2, "levels": 0, "cause": "c"}]})");
  refused(R"({"pixels": [{"x": 1, "y": 2, "levels": 256, "cause": "c"}]})");
  refused(R"({"pixels": [{"x": 1, "y": 2, "levels": 1, "cause": ""}]})");
  refused(R"({"pixels": [{"x": 1, "y": 2, "levels": 1, "cause": "c", "level": 4}]})");
  refused(R"({"max_levels_16": 17})");
  std::filesystem::remove_all(dir);
}

// Every shipped tolerance file reads, and every pixel it lists carries the
// difference measured there (the shadow-cache pixels tens of levels, the
// float32 ones 1).
TEST(PovTolerance, ShippedFilesListTheirLevels) {
  int files = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(std::filesystem::path(RAYAUDIT_SOURCE_DIR) / "scenes" / "pov")) {
    if (e.path().extension() != ".json") continue;
    ++files;
    const PovTolerance t = load_pov_tolerance(e.path());
    for (const auto& p : t.pixels) {
      EXPECT_GE(p.levels, 1) << e.path();
      if (p.cause.rfind("float32", 0) == 0) {
        EXPECT_EQ(p.levels, 1) << e.path() << " (" << p.x << ", " << p.y << ")";
      }
    }
  }
  EXPECT_GE(files, 5);
}

}  // namespace
}  // namespace ra
