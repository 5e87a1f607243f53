// Blocks of 4 triangles and rays for the 4-lane leaves' tests
// (moller_simd_test.cpp, exact_simd_test.cpp): rays with -0 components at
// triangles with vertices on the coordinate planes, through vertices and
// edges, where a hit's t, b1 or b2 is a zero whose sign the lanes must keep
// (a broadcast written 0 + x would lose it).
#pragma once
#include "../ray.h"

namespace ra {

template <class T, class F>
void for_each_signed_zero_block(F&& f) {
  const T z = T(0), nz = -T(0);
  const T comps[] = {nz, z, T(0.25), T(-0.25), T(1), T(-1)};
  const Vec3<T> v[4][3] = {{Vec3<T>(z, z, z), Vec3<T>(T(1), z, z), Vec3<T>(z, T(1), z)},
                           {Vec3<T>(nz, nz, nz), Vec3<T>(z, T(1), z), Vec3<T>(T(1), z, z)},
                           {Vec3<T>(T(-1), z, z), Vec3<T>(z, z, z), Vec3<T>(z, T(-1), z)},
                           {Vec3<T>(z, z, T(1)), Vec3<T>(T(1), z, T(1)), Vec3<T>(z, T(1), T(1))}};
  for (T ox : comps)
    for (T oy : comps)
      for (T dx : {nz, z, T(0.5)})
        for (T dy : {nz, z, T(-0.5)}) {
          Ray<T> r;
          r.o = Vec3<T>(ox, oy, T(1));
          r.d = Vec3<T>(dx, dy, T(-1));
          r.tmin = nz;
          f(r, v);
        }
}

// A point of the triangle t to aim a ray at: its vertex `corner` (kind 0),
// a point of its edge 0-1 (kind 1) or an interior point (kind 2 and up);
// `draw` gives uniform numbers in [0, 1).
template <class T, class Draw>
Vec3<T> aim_point(const Vec3<T> (&t)[3], int kind, int corner, Draw&& draw) {
  if (kind == 0) return t[corner];
  if (kind == 1) return t[0] + (t[1] - t[0]) * T(draw());
  const T s1 = T(draw() * 0.5), s2 = T(draw() * 0.5);
  return t[0] + (t[1] - t[0]) * s1 + (t[2] - t[0]) * s2;
}

}  // namespace ra
