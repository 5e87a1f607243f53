// Document 002's bounding-sphere test (seeds/002: skip a mesh whose
// bounding sphere the ray misses), the optimisation `--accel sphere` measures.
// Guarantee: conservative, inflated by a relative 1e-6 (and 1e-12 of the
// centre's and the origin's distances from the origin, beyond the rounding
// of o + d t there), so it never rejects a mesh the exact
// ray could hit within its window; the tracer adds its kernels' rounding
// to the radius (render.cpp: the BVH's padding, which covers float rays).
#pragma once
#include <algorithm>
#include <cmath>

#include "../ray.h"
#include "../vec.h"

namespace ra {

// Does the segment [tmin, tmax] of the ray pass through the solid ball?
inline bool segment_meets_ball(const Ray<double>& r, const Vec3d& c, double radius) {
  const double dd = dot(r.d, r.d);
  double t = dot(c - r.o, r.d) / dd;
  t = std::clamp(t, r.tmin, std::isfinite(r.tmax) ? r.tmax : std::max(t, r.tmin));
  const Vec3d q = r.o + r.d * t - c;
  const double rr = radius * (1 + 1e-6) + 1e-12 * (length(c) + length(r.o));
  return dot(q, q) <= rr * rr;
}

}  // namespace ra
