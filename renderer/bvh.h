// A bounding volume hierarchy over one mesh's triangles: the modern
// reference next to document 002's optimisations (backface culling, a
// bounding sphere). Binned SAH (kBins bins per axis on the centroids),
// leaves of at most kMaxLeaf triangles, nodes in depth-first order (the left
// child follows its parent).
//
// Boxes are conservative: rounded outward to float and padded by `pad`, so
// that a ray the triangle kernel would hit always enters every box on the way
// (visit order never matters: the tracer's tie-breaking in nearer() makes the
// closest hit independent of it, and box tests accept t == tmax).
#pragma once
#include <cstdint>
#include <vector>

#include "ray.h"
#include "vec.h"

namespace ra {

struct BvhNode {
  float lo[3], hi[3];
  std::uint32_t index;  // leaf: first slot; interior: the right child
  std::uint16_t count;  // leaf: number of triangles (> 0); interior: 0
  std::uint16_t axis;   // interior: split axis (near child first)
};

struct Bvh {
  static constexpr int kBins = 16;
  static constexpr int kMaxLeaf = 4;
  static constexpr int kMaxDepth = 128;  // bounds the traversal stack
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> order;  // slot -> triangle index

  // Builds over triangles given by their boxes; `pad` widens every box.
  static Bvh build(const std::vector<Vec3d>& lo, const std::vector<Vec3d>& hi, double pad);
};

// Does the ray's window [tmin, tmax] (both inclusive) meet the node's box?
// inv_d = 1 / d per component (infinite for a zero component).
inline bool ray_meets_box(const BvhNode& n, const Vec3d& o, const Vec3d& inv_d, const Vec3d& d, double tmin,
                          double tmax) {
  for (int a = 0; a < 3; ++a) {
    const double lo = n.lo[a], hi = n.hi[a];
    if (d[a] == 0) {
      if (o[a] < lo || o[a] > hi) return false;
      continue;
    }
    double t0 = (lo - o[a]) * inv_d[a], t1 = (hi - o[a]) * inv_d[a];
    if (t0 > t1) std::swap(t0, t1);
    // Slightly widened against the rounding of the two operations above.
    t0 *= t0 > 0 ? 1 - 4e-16 : 1 + 4e-16;
    t1 *= t1 > 0 ? 1 + 4e-16 : 1 - 4e-16;
    if (t0 > tmin) tmin = t0;
    if (t1 < tmax) tmax = t1;
    if (tmin > tmax) return false;
  }
  return true;
}

}  // namespace ra
