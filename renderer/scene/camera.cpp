#include "camera.h"

#include <cmath>

namespace ra {

Camera::Camera(const CameraSpec& spec, int width, int height) : origin_(spec.position), width_(width), height_(height) {
  const Vec3d f = normalize(spec.look_at - spec.position);
  // Right-handed: right = forward x up; POV gets the same frame from
  // `right -x*aspect` in its left-handed convention.
  const Vec3d right = normalize(cross(f, spec.up));
  const Vec3d up = cross(right, f);
  const double aspect = double(width) / double(height);
  const double tan_half = std::tan(spec.vfov * 0.5 * M_PI / 180.0);
  d_ = f * (0.5 / tan_half);
  r_ = right * aspect;
  u_ = up;
}

Vec3d Camera::direction(double x, double y) const {
  const double x0 = x / double(width_) - 0.5;
  const double y0 = 0.5 - y / double(height_);
  return normalize(d_ + r_ * x0 + u_ * y0);
}

}  // namespace ra
