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
  t.pixels = {{3, 4, "shadow cache"}, {5, 5, "gone"}};
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
  t.pixels = {{3, 4, "shadow cache"}};
  EXPECT_FALSE(judge(with_differences({{3, 4, 200}}), t).pass);
}

TEST(PovTolerance, At16BitsFloat32RoundingIsAllowed) {
  const PovTolerance t;
  EXPECT_TRUE(judge(with_differences({{1, 1, 2}}, 16), t).pass);
  EXPECT_FALSE(judge(with_differences({{1, 1, 3}}, 16), t).pass);
}

TEST(PovTolerance, ReadsTheFileAndRefusesUnknownKeys) {
  const auto dir = std::filesystem::temp_directory_path() / ("rayaudit-tol-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "pov");
  EXPECT_EQ(pov_tolerance_path(dir / "s.json"), dir / "pov" / "s.json");
  std::ofstream(dir / "pov" / "s.json") << R"({"notes": "n", "pixels": [{"x": 1, "y": 2, "cause": "c"}]})";
  const PovTolerance t = load_pov_tolerance(dir / "pov" / "s.json");
  ASSERT_EQ(t.pixels.size(), 1u);
  EXPECT_EQ(t.pixels[0].cause, "c");
  std::ofstream(dir / "pov" / "bad.json") << R"({"tolerance": 5})";
  EXPECT_THROW(load_pov_tolerance(dir / "pov" / "bad.json"), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ra
