// The small records an intersection kernel returns (pbrt-v4 style): only what
// the kernel knows. Building the full shading record is a separate step.
#pragma once

namespace ra {

// A ray/triangle hit. Barycentrics follow document 002:
//   P = (1 - b1 - b2) * A + b1 * B + b2 * C
// so normals and UVs interpolate as nA + b1 (nB - nA) + b2 (nC - nA).
template <class T>
struct TriangleHit {
  T t;
  T b1;
  T b2;
};

// A ray/sphere or ray/plane hit: just the parameter along the ray.
template <class T>
struct SurfaceHit {
  T t;
};

}  // namespace ra
