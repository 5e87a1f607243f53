// Image comparison: counts and positions agree with an exact integer count.
#include "image_compare.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ra {
namespace {

Image grey(int w, int h, float v) {
  Image img(w, h);
  for (auto& x : img.rgb) x = v;
  return img;
}

TEST(ImageCompare, IdenticalImagesHaveNoDifferencesAndInfinitePsnr) {
  const Image a = grey(8, 6, 0.5f);
  const ImageComparison c = compare_images(a, a, 8);
  EXPECT_TRUE(c.identical());
  EXPECT_EQ(c.pixels, 48);
  EXPECT_EQ(c.over_1, 0);
  EXPECT_EQ(c.over_4, 0);
  EXPECT_EQ(c.max_error, 0);
  EXPECT_FALSE(std::isfinite(c.psnr));
  EXPECT_TRUE(to_json(c)["psnr"].is_null());
  EXPECT_TRUE(to_json(c)["identical"].get<bool>());
}

TEST(ImageCompare, CountsPixelsOffByMoreThanOneAndFourLevels) {
  const Image a = grey(8, 6, 100 / 255.f);
  Image b = a;
  b.at(1, 0)[0] = 101 / 255.f;  // 1 level: differs, not over 1
  b.at(2, 3)[1] = 102 / 255.f;  // 2 levels: over 1
  b.at(3, 3)[2] = 104 / 255.f;  // 4 levels: over 1, not over 4
  b.at(5, 4)[0] = 110 / 255.f;  // 10 levels: over 4
  const ImageComparison c = compare_images(a, b, 8);
  EXPECT_FALSE(c.identical());
  ASSERT_EQ(c.differences.size(), 4u);
  EXPECT_EQ(c.differences[0].x, 1);
  EXPECT_EQ(c.differences[0].levels, 1);
  EXPECT_EQ(c.over_1, 3);
  EXPECT_EQ(c.over_4, 1);
  EXPECT_EQ(c.max_x, 5);
  EXPECT_EQ(c.max_y, 4);
  EXPECT_EQ(c.max_channel, 0);
  EXPECT_NEAR(c.max_error, 10 / 255.0, 1e-6);
}

TEST(ImageCompare, QuantisesBeforeComparing) {
  // Values within half a level of each other land on the same level.
  const ImageComparison c = compare_images(grey(2, 2, 0.5f), grey(2, 2, 0.5f + 0.4f / 255), 8);
  EXPECT_TRUE(c.identical());
  EXPECT_FALSE(compare_images(grey(2, 2, 0.5f), grey(2, 2, 0.5f + 0.4f / 255), 16).identical());
}

TEST(ImageCompare, DifferenceImageMarksOnlyDifferingPixels) {
  const Image a = grey(4, 4, 0.5f);
  Image b = a;
  b.at(2, 2)[0] = 0.9f;
  const Image d = difference_image(a, b, 8);
  EXPECT_GT(d.at(2, 2)[0], 0.5f);  // red: many levels
  EXPECT_EQ(d.at(2, 2)[1], 0.f);
  EXPECT_EQ(d.at(0, 0)[0], d.at(0, 0)[2]);  // grey elsewhere
  EXPECT_LT(d.at(0, 0)[0], 0.2f);
}

}  // namespace
}  // namespace ra
