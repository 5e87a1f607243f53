// The small records an intersection kernel returns (pbrt-v4 style): only what
// the kernel knows. Building the full shading record is a separate step.
#pragma once

namespace ra {

// A ray/triangle hit. Barycentrics follow document 002:
//   P = (1 - b1 - b2) * A + b1 * B + b2 * C
// so normals and UVs interpolate as nA + b1 (nB - nA) + b2 (nC - nA).
//
// alignas(16): an optional<TriangleHit<float>> would otherwise be 16 bytes,
// which GCC returns in two registers built and reread through the stack, a
// store-forwarding stall on every call that made every float method about
// 1.5x slower than its double twin (`rayaudit bench`, kernel/ rows: moller
// 10.4 ns float vs 6.9 double before, 6.6 vs 7.0 after). Aligned, it is
// returned in memory as the double one is.
template <class T>
struct alignas(16) TriangleHit {
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
