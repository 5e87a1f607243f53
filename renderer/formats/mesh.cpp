#include "mesh.h"

#include <algorithm>

namespace ra {

const TriangleRun& Mesh::run_of(std::size_t i) const {
  auto it =
      std::upper_bound(runs.begin(), runs.end(), i, [](std::size_t x, const TriangleRun& r) { return x < r.first; });
  return *(it - 1);
}

Bounds3d Mesh::bbox() const {
  Bounds3d b;
  for (const auto& p : positions) {
    b.min = vmin(b.min, p);
    b.max = vmax(b.max, p);
  }
  return b;
}

double Mesh::area() const {
  double sum = 0;
  for (const auto& t : triangles) {
    const Vec3d& a = positions[size_t(t.v[0])];
    sum += 0.5 * length(cross(positions[size_t(t.v[1])] - a, positions[size_t(t.v[2])] - a));
  }
  return sum;
}

BoundingSphere Mesh::bounding_sphere() const {
  BoundingSphere s;
  const Bounds3d b = bbox();
  if (b.empty()) return s;
  s.center = (b.min + b.max) * 0.5;
  double r2 = 0;
  for (const auto& p : positions) r2 = std::max(r2, dot(p - s.center, p - s.center));
  s.radius = std::sqrt(r2);
  return s;
}

}  // namespace ra
