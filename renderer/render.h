// The reference tracer: POV-Ray 3.7's shading model (../shared/POVRAY.md)
// over any registered intersection method, in float or double.
#pragma once
#include <memory>
#include <string>

#include "image.h"
#include "ray.h"
#include "scene.h"
#include "spawn.h"

namespace ra {

enum class Accel { none, sphere, bvh };
std::optional<Accel> parse_accel(std::string_view s);
const char* accel_name(Accel a);

struct RenderOptions {
  std::string triangle_method = "moller";
  std::string sphere_method = "stable";
  bool use_double = true;  // intersection precision; shading is always double
  bool cull = false;       // backface culling for triangles (document 002)
  Accel accel = Accel::bvh;  // none and sphere are document 002's; bvh the modern reference
  SelfIntersection self_intersection = SelfIntersection::pov;
  int threads = 0;          // 0: all cores
  int samples_per_axis = 1; // n x n samples per pixel, averaged
  bool progress = true;     // a progress line on a terminal (stderr)
};

// What a ray hit: object index, primitive (triangle) index, t and the
// barycentrics of a triangle hit.
struct SceneHit {
  double t = 0;
  int object = -1;
  int prim = -1;
  double b1 = 0, b2 = 0;
};

class Tracer {
 public:
  // Validates the options against the registry: unknown method names are
  // InputError listing the valid ones.
  Tracer(const Scene& scene, const RenderOptions& options);
  ~Tracer();
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  // The colour seen along a camera ray (level 1).
  Color trace(const Ray<double>& ray) const;
  // The closest hit of a ray, if any (the ray's own window applies).
  std::optional<SceneHit> intersect(const Ray<double>& ray) const;
  // The colour of pixel (i, j), averaging the n x n samples.
  Color pixel(int i, int j) const;
  // Renders the whole image in 32 x 32 tiles on `threads` threads; the
  // result does not depend on the thread count.
  Image render() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

inline Image render(const Scene& scene, const RenderOptions& options) {
  return Tracer(scene, options).render();
}

}  // namespace ra
