// The reference tracer: POV-Ray 3.7's shading model (../shared/POVRAY.md)
// over any registered intersection method, in float or double.
#pragma once
#include <array>
#include <memory>
#include <string>

#include "image.h"
#include "ray.h"
#include "scene/scene.h"
#include "spawn.h"

namespace ra {

enum class Accel { none, sphere, bvh };
std::optional<Accel> parse_accel(std::string_view s);
const char* accel_name(Accel a);

struct RenderOptions {
  std::string triangle_method = "moller";
  std::string sphere_method = "stable";
  bool use_double = true;    // intersection precision; shading is always double
  bool cull = false;         // backface culling for triangles (document 002)
  Accel accel = Accel::bvh;  // none and sphere are document 002's; bvh the modern reference
  SelfIntersection self_intersection = SelfIntersection::pov;
  int threads = 0;           // 0: all cores
  int samples_per_axis = 1;  // n x n samples per pixel, averaged
  bool progress = true;      // a progress line on a terminal (stderr)
  // With accel bvh, a scene of 3 or more spheres and meshes finds them
  // through a BVH over their boxes (POV-Ray's automatic bounding); false:
  // a loop over every object. The same image either way (render_test).
  bool object_bvh = true;
  // Use AVX2 where the CPU has it (false: the baseline x86-64 SSE2 paths;
  // both give the same bits, which the Accel tests check).
  bool simd = true;
  // The BVH's traversal also asks for the nodes and leaf blocks beside the
  // ones it meets (accel/bvh.h, prefetch_node): by_size where a mesh's
  // nodes and leaves exceed 32 MiB (a last-level cache), or always, or
  // never. Speed only: the same hits and images (Bvh.SameHits* and
  // ObjectBvh.SameBitsAsTheLoopOverObjects* force it on).
  enum class NeighbourPrefetch { by_size, always, never };
  NeighbourPrefetch neighbour_prefetch = NeighbourPrefetch::by_size;
  // With simd: the one-mesh entry points compiled for AVX-512 where the CPU
  // has it (false: the AVX2 ones; the tests compare both).
  bool avx512 = true;
  // Shade a mesh hit where POV-Ray 3.7's mesh2 puts it (renderer/pov_mesh.h):
  // the point O + t D with t from the triangle's float32 plane, and normals
  // and UVs interpolated there through POV's float32 Perp vector. Which
  // triangle is hit is still decided by the triangle method. A hypothesis for
  // rayaudit compare --explain, not a way to render.
  bool pov_mesh_hit = false;
  // Decide which mesh triangle a ray meets by POV-Ray 3.7's own mesh2 test
  // (renderer/pov_mesh.h: dominant-axis projection on float32 data) and its
  // bounding-box tree search (which stops at the nearest hit, even one the
  // ray's window then refuses) instead of the triangle method, for camera,
  // reflected and shadow rays alike. A hypothesis for --explain.
  bool pov_mesh_intersect = false;
  // With pov_mesh_hit: texture coordinates as POV-Ray's Mesh::UVCoord
  // computes them (renderer/pov_mesh.h), not interpolated with the normal's
  // weights. A hypothesis for --explain.
  bool pov_mesh_uv = false;
  // Colours in float32 as POV-Ray 3.7 keeps them (RGBColour is float; see
  // trace.cpp): the pigment, the finish's coefficients, the light colours and
  // every product and sum of the shading rounded to float32, in POV's order.
  // A hypothesis for --explain.
  bool float32_colour = false;
  // POV-Ray's shadow cache (../shared/POVRAY.md): the object that last
  // blocked a light is tested first, accepting t >= 1e-4. Its state runs
  // from pixel to pixel, so render() then runs on one thread in POV's +WT1
  // order; pixel() alone is not meaningful. Double precision only. A
  // hypothesis for --explain.
  bool pov_shadow_cache = false;
  // A reflected ray's hit on the very primitive it leaves, nearer than the
  // rounding of its origin allows (a plane met again far out at a grazing
  // angle), skipped: whether it happens is decided by the last bits of the
  // hit point, which POV-Ray computes differently. A hypothesis for --explain.
  bool skip_rounding_self_hits = false;
  // Shade every surface by POV-Ray 3.7's ComputeLightedTexture as the glass
  // path does (renderer/shading/glass.h), also in a scene without glass:
  // the light's direction as (L - P) times 1/|L - P| (VInverseScaleEq), each
  // light's diffuse and phong summed before they join the total, and the
  // phong highlight dropped where R.L <= 0.0008 from phong_size 60 on. The
  // same image up to the last bits of a colour. A hypothesis for --explain.
  bool pov_lighting = false;
  // A flat mesh triangle shaded with POV-Ray's float32 face normal
  // (renderer/pov_mesh.h, pov_mesh_flat_normal) instead of ours in double.
  // A hypothesis for --explain.
  bool pov_flat_normal = false;
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
  // The closest hit of a ray, if any (the ray's own window applies), as a
  // camera ray: --cull applies (the renderer never culls shadow or
  // reflected rays, which may start inside a closed mesh's silhouette).
  std::optional<SceneHit> intersect(const Ray<double>& ray) const;
  // Is anything in the ray's window? (what shadow rays ask), in the chosen
  // precision.
  bool occluded(const Ray<double>& ray) const;
  // The surface where a ray first hits: point, geometric normal and the
  // shading normal as lighting sees it before the face-forward flip
  // (interpolated for smooth meshes, with document 002's bumps applied), and
  // the UVs. nullopt on a miss. For tests and tools.
  struct ShadingPoint {
    Vec3d p, ng, n;
    bool has_uv = false;
    double u = 0, v = 0;
  };
  std::optional<ShadingPoint> shading_point(const Ray<double>& ray) const;
  // The colour of pixel (i, j), averaging the n x n samples.
  Color pixel(int i, int j) const;
  // Renders the whole image in 32 x 32 tiles on `threads` threads; the
  // result does not depend on the thread count.
  Image render() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

inline Image render(const Scene& scene, const RenderOptions& options) { return Tracer(scene, options).render(); }

}  // namespace ra
