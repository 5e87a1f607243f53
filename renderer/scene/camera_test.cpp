// Camera rays go through pixel centres, row 0 at the top (POV-Ray's rule).
#include "camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ra {
namespace {

constexpr double kTol = 1e-15;

void expect_dir(const Vec3d& got, const Vec3d& want) {
  const Vec3d w = normalize(want);
  EXPECT_NEAR(got.x, w.x, kTol);
  EXPECT_NEAR(got.y, w.y, kTol);
  EXPECT_NEAR(got.z, w.z, kTol);
}

TEST(Camera, CornerPixelCentresOfA2x2ImageAtVfov90) {
  // vfov 90: tan(45) = 1, so |D| = 0.5; aspect 1: |R| = |U| = 1. Looking down
  // -z from the origin with y up, right is +x. Pixel (0,0) is the top-left:
  // x0 = 0.5/2 - 0.5 = -0.25, y0 = 0.5 - 0.5/2 = +0.25.
  CameraSpec spec{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90};
  Camera cam(spec, 2, 2);
  expect_dir(cam.direction(0.5, 0.5), {-0.25, 0.25, -0.5});
  expect_dir(cam.direction(1.5, 0.5), {0.25, 0.25, -0.5});
  expect_dir(cam.direction(0.5, 1.5), {-0.25, -0.25, -0.5});
  expect_dir(cam.direction(1.5, 1.5), {0.25, -0.25, -0.5});
}

TEST(Camera, CentrePixelOfAnOddImageLooksStraightAhead) {
  CameraSpec spec{{1, 2, 3}, {1, 2, -7}, {0, 1, 0}, 30};
  Camera cam(spec, 5, 3);
  expect_dir(cam.direction(2.5, 1.5), {0, 0, -1});
  EXPECT_EQ(cam.ray(2.5, 1.5).o, Vec3d(1, 2, 3));
}

TEST(Camera, WideImageSpansAspectTimesTheVerticalExtent) {
  // 4x2 image, vfov 90: the right edge of the image (x = 4) is at
  // x0 = 0.5, so dir = D + 0.5 R with |D| = 0.5, |R| = 2: (1, 0, -0.5).
  CameraSpec spec{{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90};
  Camera cam(spec, 4, 2);
  expect_dir(cam.direction(4, 1), {1, 0, -0.5});
  // The top edge at the centre column: y0 = 0.5: (0, 0.5, -0.5), 45 degrees up.
  expect_dir(cam.direction(2, 0), {0, 0.5, -0.5});
}

}  // namespace
}  // namespace ra
