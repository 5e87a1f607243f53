#include "pov_explain.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "scene/camera.h"
#include "pov_mesh.h"
#include "spawn.h"

namespace ra {
namespace {

// The scene as POV-Ray's mesh2 holds it: with `float32`, every mesh's
// vertices and normals rounded to float32 (SNGL_VECT; its UVs are double,
// UV_VECT); with `flatten`, each smooth triangle POV-Ray makes flat (given
// the normal of its vertices): Parse_Mesh2's "check for equal normals" calls
// a triangle flat when |N1 - N2|^2 and |N1 - N3|^2 are both at most EPSILON
// (1e-10), the differences taken of the float32 normals.
// Parse_Mesh2's test on two normals (float32 values): VSub of two float
// vectors subtracts in float, VDot sums the squares in double.
bool pov_equal_normals(const Vec3d& a, const Vec3d& b) {
  const Vec3d d = to_float32(a - b);
  return !(std::fabs(dot(d, d)) > 1e-10);
}

Scene as_pov_stores_it(const Scene& scene, bool float32, bool flatten) {
  Scene s = scene;
  for (auto& o : s.objects) {
    if (o.kind != Object::Kind::mesh) continue;
    auto set = std::make_shared<TriangleSet>(*o.mesh);
    if (float32 && set->shading == Shading::smooth) {
      // Triangles without vn: the exporter hands POV the area-weighted vertex
      // normals of the unrounded vertices (pov_export.cpp), so do the same
      // here before rounding; left to the renderer, they would come from the
      // float32 vertices and never be rounded themselves.
      bool need_computed = false;
      for (const auto& tri : set->triangles) need_computed |= tri.n[0] < 0 || tri.n[1] < 0 || tri.n[2] < 0;
      if (need_computed) {
        const int base = int(set->normals.size());
        const auto vn = area_weighted_vertex_normals(*set);
        set->normals.insert(set->normals.end(), vn.begin(), vn.end());
        for (auto& tri : set->triangles)
          if (tri.n[0] < 0 || tri.n[1] < 0 || tri.n[2] < 0) tri.n = {base + tri.v[0], base + tri.v[1], base + tri.v[2]};
      }
    }
    if (float32) {
      // to_float32, not Vec3d(Vec3f(p)): GCC 12.2 drops that rounding in x
      // and y (renderer/pov_mesh.h).
      for (auto& p : set->positions) p = to_float32(p);
      for (auto& n : set->normals) {
        const double len = length(n);
        if (len > 0) n = to_float32(n / len);
      }
    }
    if (flatten && set->shading == Shading::smooth) {
      for (auto& tri : set->triangles) {
        if (tri.n[0] < 0 || tri.n[1] < 0 || tri.n[2] < 0) continue;
        const Vec3d &na = set->normals[tri.n[0]], &nb = set->normals[tri.n[1]], &nc = set->normals[tri.n[2]];
        if (!(pov_equal_normals(na, nb) && pov_equal_normals(na, nc))) continue;
        const Vec3d &a = set->positions[tri.v[0]], &b = set->positions[tri.v[1]], &c = set->positions[tri.v[2]];
        Vec3d g = normalize(cross(b - a, c - a));
        if (dot(g, na) < 0) g = -g;
        set->normals.push_back(g);
        const int gi = int(set->normals.size()) - 1;
        tri.n = {gi, gi, gi};
      }
    }
    o.mesh = set;
  }
  return s;
}

// RAYAUDIT_EXPLAIN_SKIP: a comma-separated list of cause names (the text
// before the colon, e.g. "shadow cache,float32") that --explain leaves out.
// For developers asking "what would be left without this rule", and for the
// test that a batch with an unexplained pixel exits 1 and writes its minimal
// scene (cli/pov_cli_test.cpp).
std::set<std::string> skipped_causes() {
  std::set<std::string> out;
  const char* env = std::getenv("RAYAUDIT_EXPLAIN_SKIP");
  if (!env) return out;
  std::string_view rest(env);
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view name = rest.substr(0, comma);
    if (!name.empty()) out.emplace(name);
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  return out;
}

bool is_skipped(const std::set<std::string>& skip, std::string_view cause) {
  return skip.count(std::string(cause.substr(0, cause.find(':')))) > 0;
}

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

std::string float32_colour_cause(const float* ours, const float* pov, unsigned max) {
  // Every channel that differs is one level apart, and ours lies within a
  // few float32 ulps of the boundary between the two levels, k + 0.5 (a hit
  // against a miss, or a channel two levels off, is not this).
  int near_ch = -1;
  double near_scaled = 0;
  for (int ch = 0; ch < 3; ++ch) {
    const float v = ours[ch];
    const unsigned qo = quantize(v, max), qp = quantize(pov[ch], max);
    if (qo == qp) continue;
    const double scaled = double(v) * max;
    const double boundary = std::min(qo, qp) + 0.5;
    const double ulp = double(std::nextafter(v, 2.f) - v) * max;
    if (!(qo + 1 == qp || qp + 1 == qo) || !(std::abs(scaled - boundary) <= 4 * ulp)) return {};
    near_ch = ch, near_scaled = scaled;
  }
  if (near_ch < 0) return {};
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "float32 colour: our channel %d is %.9g levels, within 4 float32 ulps of a rounding boundary "
                "(k + 0.5); POV-Ray computes colours in float32, so its value falls on the other side",
                near_ch, near_scaled);
  return buf;
}

std::vector<PixelExplanation> explain_differences(const Scene& scene, const Image& ours, const Image& pov,
                                                  const ImageComparison& c, const RenderOptions& options) {
  std::vector<PixelExplanation> out;
  if (c.differences.empty()) return out;
  RenderOptions quiet = options;
  quiet.progress = false;
  RenderOptions pov_hit = quiet;
  pov_hit.pov_mesh_hit = true;
  RenderOptions pov_isect = pov_hit;
  pov_isect.pov_mesh_intersect = true;
  RenderOptions pov_uv = pov_isect;
  pov_uv.pov_mesh_uv = true;
  RenderOptions pov_f32 = pov_uv;
  pov_f32.float32_colour = true;
  RenderOptions f32_only = quiet;
  f32_only.float32_colour = true;
  RenderOptions no_self_hit = quiet;
  no_self_hit.skip_rounding_self_hits = true;
  RenderOptions pov_light = quiet;
  pov_light.pov_lighting = true;
  RenderOptions pov_light_f32 = pov_light;
  pov_light_f32.float32_colour = true;
  RenderOptions pov_light_mesh = pov_f32;
  pov_light_mesh.pov_lighting = true;
  RenderOptions flat_normal = pov_f32;
  flat_normal.pov_flat_normal = true;
  RenderOptions flat_normal_light = pov_light_mesh;
  flat_normal_light.pov_flat_normal = true;
  struct Model {
    const char* cause;
    Scene scene;
    RenderOptions options;
  };
  const Model models[] = {
      {"float32: with the mesh's vertices and normals rounded to float32, as POV-Ray's mesh2 stores them "
       "(SNGL_VECT; its UVs are double), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, false), quiet},
      {"equal normals: POV-Ray makes a triangle flat, with the normal of its vertices rather than the given ones, "
       "when its three float32 normals are equal within |N1 - N2|^2 <= 1e-10 and |N1 - N3|^2 <= 1e-10 "
       "(Parse_Mesh2); done so (and with float32 mesh data), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), quiet},
      {"mesh2 hit point: POV-Ray puts the hit at O + t D with t from the triangle's plane stored as float32 (its "
       "unit normal and distance), off the plane of the vertices, and interpolates the smooth normal there "
       "through its Perp vector, computed in float32 step by step (compute_smooth_triangle of shape/mesh.cpp, "
       "the SNGL_VECT overloads of math/vector.h); done so (with float32 mesh data and equal normals "
       "flat), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), pov_hit},
      {"mesh2 intersection: POV-Ray decides whether a ray meets a mesh2 triangle by projecting the point on its "
       "float32 plane along the dominant axis of the normal and testing the three edges in 2D on the float32 "
       "vertices (intersect_mesh_triangle), and its bounding-box tree search stops at the box entered after the "
       "nearest hit, even a hit the caller then refuses as too close (a neighbouring triangle at t < 1e-3 hides the "
       "rest of the mesh from a shadow ray) (shape/mesh.cpp); deciding every camera, reflected and shadow ray's "
       "mesh hits so (with its hit point, float32 data and equal normals flat), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), pov_isect},
      {"mesh2 UV: POV-Ray computes a mesh2 hit's texture coordinates by its own projection onto the float32 "
       "triangle sides (Mesh::UVCoord of shape/mesh.cpp), not with the smooth normal's weights; done so at its hit "
       "point (with its inside test, float32 data and equal normals flat), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), pov_uv},
      {"float32 shading: POV-Ray keeps colours in float32 (RGBColour): the pigment, finish colours, light colours "
       "and every product and sum of the shading rounded to float32 (trace.cpp); shaded so (with all the mesh2 "
       "rules above), our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), pov_f32},
      {"float32 shading: POV-Ray keeps colours in float32 (RGBColour): the pigment, finish colours, light colours "
       "and every product and sum of the shading rounded to float32 (trace.cpp); shaded so, our pixel equals "
       "POV-Ray's",
       scene, f32_only},
      {"rounding self-hit: our reflected ray meets the primitive it leaves again, nearer than the rounding of its "
       "origin allows (at a grazing angle far away the hit point's last bits put it on one side of the surface or "
       "the other, and POV-Ray computes them differently); without that self-hit our pixel equals POV-Ray's",
       scene, no_self_hit},
      {"POV lighting: POV-Ray's ComputeLightedTexture takes the light's direction as (L - P) times 1/|L - P| "
       "(VInverseScaleEq), not divided by |L - P|, sums each light's diffuse and phong before adding them, and "
       "drops a highlight where R.L <= 0.0008 from phong_size 60 on (trace.cpp); shaded so, our pixel equals POV-Ray's",
       scene, pov_light},
      {"POV lighting in float32: POV-Ray's ComputeLightedTexture as above (the light's direction times 1/|L - P|, "
       "each light's diffuse and phong summed first) with its colours in float32 (RGBColour); shaded so, our pixel "
       "equals POV-Ray's",
       scene, pov_light_f32},
      {"POV lighting in float32 with every mesh2 rule: POV-Ray's ComputeLightedTexture as above in float32, at "
       "its mesh2 hit point with its inside test, float32 mesh data and equal normals flat; shaded so, our pixel "
       "equals POV-Ray's",
       as_pov_stores_it(scene, true, true), pov_light_mesh},
      {"flat mesh2 normal: POV-Ray shades a flat mesh2 triangle with its face normal (C - A) x (B - A) of the "
       "float32 vertices, times 1/length, stored as float32 (Compute_Mesh_Triangle, Mesh_Hash_Normal); shaded so, "
       "with every mesh2 rule and float32 colours, our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), flat_normal},
      {"flat mesh2 normal with POV lighting: POV-Ray's float32 face normal of a flat mesh2 triangle, its "
       "ComputeLightedTexture (the light's direction times 1/|L - P|, each light's terms summed first), every mesh2 "
       "rule and float32 colours; shaded so, our pixel equals POV-Ray's",
       as_pov_stores_it(scene, true, true), flat_normal_light},
  };
  std::vector<std::unique_ptr<Tracer>> model_tracers;
  for (const auto& m : models) model_tracers.push_back(std::make_unique<Tracer>(m.scene, m.options));
  constexpr std::size_t kAllMeshRules = 5;  // the float32 shading model with every mesh2 rule
  const Model cache_models[] = {
      {"shadow cache: POV-Ray first re-tests the object that last blocked the light (one cache for camera-ray hits, "
       "one for deeper ones), accepting t >= 1e-4 where the ordinary test wants t > 1e-3 (trace.cpp, "
       "TracePointLightShadowRay); the image rendered so in POV's order, our pixel equals POV-Ray's",
       scene, quiet},
      {"shadow cache: POV-Ray first re-tests the object that last blocked the light, accepting t >= 1e-4 where the "
       "ordinary test wants t > 1e-3 (trace.cpp); the image rendered so in POV's order, with every mesh2 rule and "
       "float32 colours, our pixel equals POV-Ray's",
       models[kAllMeshRules].scene, models[kAllMeshRules].options},
  };
  std::optional<Image> cache_images[std::size(cache_models)];
  const Tracer tracer(scene, quiet);
  const Camera camera(scene.camera, scene.width, scene.height);
  const unsigned m = c.bits == 16 ? 65535u : 255u;
  const std::set<std::string> skip = skipped_causes();
  for (const auto& d : c.differences) {
    PixelExplanation e{d.x, d.y, d.levels, ""};
    for (std::size_t mi = 0; mi < model_tracers.size() && e.cause.empty(); ++mi) {
      if (is_skipped(skip, models[mi].cause)) continue;
      const Color rc = model_tracers[mi]->pixel(d.x, d.y);
      const float rf[3] = {float(rc.x), float(rc.y), float(rc.z)};
      bool same = true;
      for (int ch = 0; ch < 3; ++ch) same &= quantize(rf[ch], m) == quantize(pov.at(d.x, d.y)[ch], m);
      if (same) e.cause = models[mi].cause;
    }
    // POV's shadow cache: the whole image rendered in POV's order with it
    // (its state runs from pixel to pixel), alone and with every rule above.
    for (std::size_t ci = 0; ci < std::size(cache_models) && e.cause.empty(); ++ci) {
      if (is_skipped(skip, cache_models[ci].cause)) continue;
      if (!cache_images[ci]) {
        RenderOptions o = cache_models[ci].options;
        o.pov_shadow_cache = true;
        cache_images[ci] = Tracer(cache_models[ci].scene, o).render();
      }
      bool same = true;
      for (int ch = 0; ch < 3; ++ch)
        same &= quantize(cache_images[ci]->at(d.x, d.y)[ch], m) == quantize(pov.at(d.x, d.y)[ch], m);
      if (same) e.cause = cache_models[ci].cause;
    }
    if (e.cause.empty() && !is_skipped(skip, "float32 colour"))
      e.cause = float32_colour_cause(ours.at(d.x, d.y), pov.at(d.x, d.y), m);
    if (!e.cause.empty()) {
      out.push_back(e);
      continue;
    }
    // POV's shadow cache
    Ray<double> r = camera.ray(d.x + 0.5, d.y + 0.5);
    r.tmin = kPovMinIsectDepth;
    if (const auto hit = tracer.intersect(r);
        !is_skipped(skip, "shadow cache") && hit && luminance(pov.at(d.x, d.y)) < luminance(ours.at(d.x, d.y))) {
      const Vec3d p = r.at(hit->t);
      for (std::size_t li = 0; li < scene.lights.size(); ++li) {
        const Vec3d lv = scene.lights[li].position - p;
        const Ray<double> probe{p, normalize(lv), kPovMinIsectDepth, kPovShadowTolerance};
        if (const auto b = tracer.intersect(probe)) {
          char buf[400];
          std::snprintf(buf, sizeof buf,
                        "shadow cache: the shadow ray to light %zu meets object %d (triangle %d) at t = %.3g, inside "
                        "[1e-4, 1e-3], where POV-Ray's re-test of the previous shadow ray's blocker accepts it and "
                        "our (and POV's ordinary) window (1e-3, dist - 1e-3) does not: POV's pixel is darker",
                        li, b->object, b->prim, b->t);
          e.cause = buf;
          break;
        }
      }
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace ra
