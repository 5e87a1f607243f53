// Random scenes for `rayaudit compare --random`; see
// random_scene.h. Each draw is explicit so a scene is a pure function of
// (seed, index) and of which corpus files exist.
#include "random_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>

#include "scene/scene_mesh.h"

namespace ra {
namespace {

using json = nlohmann::json;

// Corpus meshes of up to ~10k triangles (../shared/CORPUS.md), and images.
constexpr const char* kMeshes[] = {
    "ladder/box.obj",          "ladder/cornell_box.obj",     "ladder/cube_poly_cgal.obj", "ladder/spider.obj",
    "ladder/teapot.obj",       "ladder/bunny_npm.obj",       "ladder/elephant_cgal.obj",  "ladder/cheese-ball.obj",
    "assimp-obj/WusonOBJ.obj", "assimp-obj/cube_usemtl.obj", "assimp-obj/empty_mat.obj",  "assimp-obj/regr01.obj",
    "embree/cornell_box.obj",  "generated/teapot.obj",
};
constexpr const char* kTextures[] = {
    "ladder/wal67ar_small.jpg", "ladder/wal69ar_small.jpg", "ladder/drkwood2.jpg",
    "ladder/SpiderTex.jpg",     "ladder/engineflare1.jpg",
};

std::filesystem::path corpus_file(const std::string& rel) { return cache_dir() / "corpus" / rel; }

// What the generator needs to know of a mesh: its bounding box and whether
// it has texture coordinates. Read from the `v` and `vt` lines (no loader
// warnings), once per file.
struct MeshInfo {
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  bool has_uv = false;
};

const MeshInfo& mesh_info(const std::string& rel) {
  static std::mutex mu;
  static std::map<std::string, MeshInfo> cache;
  std::lock_guard lock(mu);
  if (auto it = cache.find(rel); it != cache.end()) return it->second;
  MeshInfo info;
  std::ifstream in(corpus_file(rel));
  int vt = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("vt ", 0) == 0) ++vt;
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream ss(line.substr(2));
    Vec3d p;
    if (ss >> p.x >> p.y >> p.z) {
      info.lo = vmin(info.lo, p);
      info.hi = vmax(info.hi, p);
    }
  }
  info.has_uv = vt > 1;
  return cache.emplace(rel, info).first->second;
}

class Draw {
 public:
  Draw(std::uint64_t seed, int index) {
    std::seed_seq seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(index)};
    rng_.seed(seq);
    // Glass is drawn from a stream of its own, so that a seed's scene is
    // the same as before glass existed, with some materials made glass.
    std::seed_seq glass_seq{std::uint32_t(seed), std::uint32_t(seed >> 32), std::uint32_t(index), 0x6c617373u};
    glass_.seed(glass_seq);
  }
  double glass_uniform(double lo, double hi) { return lo + (hi - lo) * std::generate_canonical<double, 53>(glass_); }
  double glass_nice(double lo, double hi) { return std::round(glass_uniform(lo, hi) * 1000) / 1000; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * std::generate_canonical<double, 53>(rng_); }
  int integer(int lo, int hi) { return lo + int(rng_() % std::uint64_t(hi - lo + 1)); }  // inclusive
  bool chance(double p) { return uniform(0, 1) < p; }
  // Rounded to 3 decimals so that the scene file reads well.
  double nice(double lo, double hi) { return std::round(uniform(lo, hi) * 1000) / 1000; }
  json vec(double lo, double hi) { return json::array({nice(lo, hi), nice(lo, hi), nice(lo, hi)}); }
  Vec3d unit() {
    for (;;) {
      const Vec3d v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
      const double l = length(v);
      if (l > 0.1 && l <= 1) return v / l;
    }
  }
  template <class C>
  const auto& pick(const C& c) {
    return c[std::size_t(integer(0, int(std::size(c)) - 1))];
  }

 private:
  std::mt19937_64 rng_;
  std::mt19937_64 glass_;
};

json to_json(const Vec3d& v) {
  auto r = [](double x) { return std::round(x * 1000) / 1000; };
  return json::array({r(v.x), r(v.y), r(v.z)});
}

json colour(Draw& d) { return d.chance(0.3) ? json(d.nice(0.1, 1)) : d.vec(0.05, 1); }

json material(Draw& d, bool with_uv) {
  json m;
  m["color"] = colour(d);
  m["ambient"] = d.chance(0.2) ? d.vec(0, 0.3) : json(d.nice(0, 0.3));
  m["diffuse"] = d.nice(0.2, 0.9);
  if (d.chance(0.5)) {
    m["phong"] = d.nice(0.1, 1);
    m["phong_size"] = d.nice(1, 200);
  }
  if (d.chance(0.4)) m["reflection"] = d.chance(0.3) ? d.vec(0.05, 0.8) : json(d.nice(0.05, 0.8));
  // One material in four lets light through: transmit and/or filter, an ior
  // from 1 (no bending) to 2.4, Fresnel reflection in half of them.
  if (d.glass_uniform(0, 1) < 0.25) {
    const double kind = d.glass_uniform(0, 1);
    if (kind < 0.7) m["transmit"] = d.glass_nice(0.3, 0.95);
    if (kind > 0.4) m["filter"] = d.glass_nice(0.1, 1 - m.value("transmit", 0.0));
    m["ior"] = d.glass_uniform(0, 1) < 0.2 ? 1.0 : d.glass_nice(1.05, 2.4);
    if (d.glass_uniform(0, 1) < 0.5) {
      m["fresnel"] = true;
      m["reflection"] = d.glass_nice(0.3, 1);
    }
  }
  if (with_uv && d.chance(0.6)) {
    const auto tex = random_scene_textures();
    if (!tex.empty()) m["texture"] = {{"file", d.pick(tex)}, {"filter", d.chance(0.7) ? "bilinear" : "nearest"}};
  }
  return m;
}

json sphere(Draw& d) {
  return {{"sphere", {{"center", d.vec(-1.5, 1.5)}, {"radius", d.nice(0.15, 1)}}}, {"material", material(d, false)}};
}

json plane(Draw& d) {
  Vec3d n{d.uniform(-0.4, 0.4), 1, d.uniform(-0.4, 0.4)};
  if (d.chance(0.25)) n = d.unit();  // any orientation now and then
  return {{"plane", {{"normal", to_json(normalize(n))}, {"offset", d.nice(-1.5, -0.3)}}},
          {"material", material(d, false)}};
}

json triangle(Draw& d) {
  const Vec3d c{d.uniform(-1.2, 1.2), d.uniform(-1.2, 1.2), d.uniform(-1.2, 1.2)};
  json t = json::array();
  for (int k = 0; k < 3; ++k) t.push_back(to_json(c + d.unit() * d.uniform(0.3, 1.2)));
  return {{"triangle", t}, {"material", material(d, false)}};
}

json mesh(Draw& d, const std::vector<std::string>& meshes) {
  const std::string rel = d.pick(meshes);
  const MeshInfo& info = mesh_info(rel);
  json o;
  o["mesh"] = "${cache}/corpus/" + rel;
  o["shading"] = d.chance(0.5) ? "smooth" : "flat";
  std::vector<std::pair<char, double>> rot;
  json jr = json::array();
  for (int k = d.integer(0, 2); k > 0; --k) {
    const char axis = "xyz"[d.integer(0, 2)];
    const double a = d.nice(-3.14, 3.14);
    rot.push_back({axis, a});
    jr.push_back(json::array({std::string(1, axis), a}));
  }
  if (!jr.empty()) o["rotate"] = jr;
  // Fit the mesh's bounding box into a ball of radius `size` around `at`.
  const double radius = std::max(length(info.hi - info.lo) / 2, 1e-9);
  const double size = d.uniform(0.5, 1.5);
  const double scale = std::round(size / radius * 1e6) / 1e6;
  Vec3d centre = (info.lo + info.hi) * 0.5;
  for (const auto& [axis, a] : rot) centre = rotate_about(axis, a, centre);
  const Vec3d at{d.uniform(-1.2, 1.2), d.uniform(-1, 1), d.uniform(-1.2, 1.2)};
  o["scale"] = scale;
  o["translate"] = to_json(at - centre * scale);
  if (d.chance(0.6)) o["material"] = material(d, info.has_uv);  // else its MTL materials
  return o;
}

}  // namespace

std::vector<std::string> random_scene_meshes() {
  std::vector<std::string> out;
  for (const char* m : kMeshes)
    if (std::filesystem::is_regular_file(corpus_file(m))) out.push_back(m);
  return out;
}

std::vector<std::string> random_scene_textures() {
  std::vector<std::string> out;
  for (const char* t : kTextures)
    if (std::filesystem::is_regular_file(corpus_file(t))) out.push_back(std::string("${cache}/corpus/") + t);
  return out;
}

json random_scene(std::uint64_t seed, int index) {
  Draw d(seed, index);
  json s;
  static constexpr std::array<std::array<int, 2>, 4> kSizes{{{160, 120}, {120, 90}, {96, 96}, {80, 60}}};
  const auto& size = d.pick(kSizes);
  s["width"] = size[0];
  s["height"] = size[1];
  // A camera 4 to 9 away, above the horizon mostly, looking near the origin.
  Vec3d dir = d.unit();
  dir.y = std::abs(dir.y) * (d.chance(0.85) ? 1 : -1);
  s["camera"] = {{"position", to_json(dir * d.uniform(4, 9))}, {"look_at", d.vec(-0.5, 0.5)}, {"vfov", d.nice(25, 65)}};
  if (d.chance(0.2)) s["camera"]["up"] = to_json(normalize(Vec3d{d.uniform(-0.5, 0.5), 1, d.uniform(-0.5, 0.5)}));
  s["background"] = d.chance(0.5) ? d.vec(0, 0.6) : json(0);
  if (d.chance(0.3)) s["ambient_light"] = colour(d);
  s["max_depth"] = d.integer(1, 6);
  static constexpr std::array<double, 5> kBailouts{1.0 / 255, 0.01, 0.05, 0.2, 0.5};
  s["adc_bailout"] = d.pick(kBailouts);
  json lights = json::array();
  for (int k = d.integer(1, 3); k > 0; --k) {
    // Most lights outside the objects' region; now and then one among them.
    const Vec3d p = d.chance(0.8) ? d.unit() * d.uniform(3, 10) + Vec3d{0, 2, 0} : d.unit() * d.uniform(0.5, 2);
    lights.push_back({{"position", to_json(p)}, {"color", d.chance(0.4) ? json(d.nice(0.3, 1)) : d.vec(0.2, 1)}});
  }
  s["lights"] = lights;
  const auto meshes = random_scene_meshes();
  json objects = json::array();
  if (d.chance(0.6)) objects.push_back(plane(d));
  for (int k = d.integer(1, 5); k > 0; --k) {
    const double r = d.uniform(0, 1);
    if (r < 0.35 && !meshes.empty())
      objects.push_back(mesh(d, meshes));
    else if (r < 0.7)
      objects.push_back(sphere(d));
    else if (r < 0.85)
      objects.push_back(triangle(d));
    else
      objects.push_back(plane(d));
  }
  s["objects"] = objects;
  return s;
}

}  // namespace ra
