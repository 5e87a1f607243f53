// A pinhole camera that shoots one ray through each pixel CENTRE, row 0 at
// the top, exactly as POV-Ray 3.7's perspective camera (tracepixel.cpp):
//   dir = D + ((i + 0.5)/W - 0.5) R + (0.5 - (j + 0.5)/H) U,  normalised,
// with |R| = W/H, |U| = 1 and |D| = 0.5 / tan(vfov / 2).
#pragma once
#include "../ray.h"
#include "scene.h"

namespace ra {

class Camera {
 public:
  Camera(const CameraSpec& spec, int width, int height);
  // Unit direction through image position (x, y) in pixels, where pixel
  // (i, j) spans [i, i+1) x [j, j+1); its centre is (i + 0.5, j + 0.5).
  Vec3d direction(double x, double y) const;
  Ray<double> ray(double x, double y) const { return {origin_, direction(x, y)}; }
  const Vec3d& origin() const { return origin_; }
  const Vec3d& forward() const { return d_; }
  const Vec3d& right() const { return r_; }
  const Vec3d& up() const { return u_; }

 private:
  Vec3d origin_, d_, r_, u_;
  int width_, height_;
};

}  // namespace ra
