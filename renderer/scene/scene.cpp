// Scene files: strict JSON (unknown keys and wrong types are errors naming
// the JSON path) where every field has a default.
#include "scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "../errors.h"
#include "../io/file_identity.h"
#include "../io/input_file.h"
#include "../io/json_input.h"
#include "scene_mesh.h"

namespace ra {
namespace {

using json = nlohmann::json;

// "file not found: PATH" as before, or what the path is instead of a file
// (a directory, a FIFO that would block, a device); empty when it is one.
std::string file_problem(const std::filesystem::path& p) {
  const std::string why = input_file_problem(p);
  if (why.empty()) {
    note_input(p);  // a texture or mesh is never replaced by an output
    return why;
  }
  return why == "no such file" ? "file not found: " + p.string() : p.string() + ": " + why;
}

// Reads one JSON object, remembering its path for error messages and which
// keys were used, so that a misspelt key is an error rather than ignored.
class ObjectReader {
 public:
  ObjectReader(const json& j, std::string path, const std::string& file) : j_(j), path_(std::move(path)), file_(file) {
    if (!j_.is_object()) fail(path_, "expected an object");
  }

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InputError(located(file_, 0, where + ": " + what));  // control bytes in a key or path escaped
  }
  std::string at(const std::string& key) const { return path_ + "/" + key; }
  bool has(const std::string& key) {
    known_.insert(key);
    return j_.contains(key);
  }
  const json& get(const std::string& key) {
    known_.insert(key);
    return j_.at(key);
  }

  // Scene numbers are bounded: a camera at 1e308 or a radius of 1e308 gave
  // an all-black image (their squares overflow), a scale of 1e-320 too.
  static constexpr double kMaxMagnitude = 1e30, kMinPositive = 1e-30;
  static constexpr const char* kMagnitudeRule = "magnitude above 1e30 (its square would overflow a double's products)";

  double number(const std::string& key, double def) {
    if (!has(key)) return def;
    const json& v = j_.at(key);
    if (!v.is_number()) fail(at(key), "expected a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(at(key), "expected a finite number");
    if (std::fabs(d) > kMaxMagnitude) fail(at(key), kMagnitudeRule);
    return d;
  }
  double positive(const std::string& key, double def) {
    const double d = number(key, def);
    if (!(d > 0)) fail(at(key), "must be greater than 0");
    if (d < kMinPositive) fail(at(key), "must be at least 1e-30 (smaller sizes vanish in a double's products)");
    return d;
  }
  int integer(const std::string& key, int def, int lo, int hi) {
    if (!has(key)) return def;
    const json& v = j_.at(key);
    if (!v.is_number_integer()) fail(at(key), "expected an integer, got " + std::string(v.type_name()));
    const long long x = v.get<long long>();
    if (x < lo || x > hi) fail(at(key), "must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return int(x);
  }
  bool boolean(const std::string& key, bool def) {
    if (!has(key)) return def;
    const json& v = j_.at(key);
    if (!v.is_boolean()) fail(at(key), "expected true or false");
    return v.get<bool>();
  }
  std::string string(const std::string& key, const std::string& def) {
    if (!has(key)) return def;
    const json& v = j_.at(key);
    if (!v.is_string()) fail(at(key), "expected a string, got " + std::string(v.type_name()));
    return v.get<std::string>();
  }
  static Vec3d as_vec3(const json& v, const std::string& where, const ObjectReader& r) {
    if (!v.is_array() || v.size() != 3) r.fail(where, "expected an array of 3 numbers");
    Vec3d out;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) r.fail(where + "/" + std::to_string(i), "expected a number");
      out[i] = v[i].get<double>();
      if (!std::isfinite(out[i])) r.fail(where + "/" + std::to_string(i), "expected a finite number");
      if (std::fabs(out[i]) > kMaxMagnitude) r.fail(where + "/" + std::to_string(i), kMagnitudeRule);
    }
    return out;
  }
  Vec3d vec3(const std::string& key, Vec3d def) {
    if (!has(key)) return def;
    return as_vec3(j_.at(key), at(key), *this);
  }
  // A colour: [r, g, b] or one number for grey.
  Color color(const std::string& key, Color def) {
    if (!has(key)) return def;
    const json& v = j_.at(key);
    if (v.is_number()) {
      const double g = v.get<double>();
      return {g, g, g};
    }
    return as_vec3(v, at(key), *this);
  }
  // Call after reading: every key present must have been read.
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (!known_.count(it.key())) fail(at(it.key()), "unknown key");
  }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

 private:
  const json& j_;
  std::string path_;
  std::string file_;
  std::set<std::string> known_;
};

TextureFilter parse_filter(ObjectReader& r, const std::string& key) {
  const std::string f = r.string(key, "bilinear");
  if (f == "nearest") return TextureFilter::nearest;
  if (f == "bilinear") return TextureFilter::bilinear;
  r.fail(r.at(key), "expected \"nearest\" or \"bilinear\", got \"" + f + "\"");
}

// A path no file system takes (PATH_MAX, 4096 bytes) is said as such, not
// looked up and quoted whole (a 100 MB "mesh" string).
std::string path_string(ObjectReader& r, const std::string& key) {
  std::string p = r.string(key, "");
  if (p.size() >= 4096)
    r.fail(r.at(key), "a path of " + std::to_string(p.size()) + " bytes, longer than a path can be (4095 bytes)");
  return p;
}

std::filesystem::path resolve(const std::filesystem::path& scene_file, const std::string& p) {
  if (auto cached = expand_cache_prefix(p)) return *cached;  // "${cache}/..."
  std::filesystem::path q(p);
  if (q.is_relative()) q = scene_file.parent_path() / q;
  return q;
}

Material parse_material(const json& j, const std::string& path, const std::filesystem::path& file, Material m = {}) {
  ObjectReader r(j, path, file.string());
  m.color = r.color("color", m.color);
  m.ambient = r.color("ambient", m.ambient);
  m.diffuse = r.number("diffuse", m.diffuse);
  m.phong = r.number("phong", m.phong);
  m.phong_size = r.number("phong_size", m.phong_size);
  m.reflection = r.color("reflection", m.reflection);
  m.filter = r.number("filter", m.filter);
  if (!(m.filter >= 0 && m.filter <= 1)) r.fail(r.at("filter"), "must be between 0 and 1");
  m.transmit = r.number("transmit", m.transmit);
  if (!(m.transmit >= 0 && m.transmit <= 1)) r.fail(r.at("transmit"), "must be between 0 and 1");
  m.ior = r.number("ior", m.ior);
  if (!(m.ior > 0)) r.fail(r.at("ior"), "must be greater than 0");
  m.fresnel = r.boolean("fresnel", m.fresnel);
  if (r.has("texture")) {
    const json& t = r.get("texture");
    ImageTexture tex;
    if (t.is_string()) {
      tex.file = resolve(file, path_string(r, "texture"));
    } else {
      ObjectReader tr(t, r.at("texture"), file.string());
      if (!tr.has("file")) tr.fail(tr.path(), "missing key \"file\"");
      tex.file = resolve(file, path_string(tr, "file"));
      tex.filter = parse_filter(tr, "filter");
      tr.finish();
    }
    if (const auto why = file_problem(tex.file); !why.empty()) r.fail(r.at("texture"), why);
    m.texture = tex;
  }
  if (r.has("bump")) {
    ObjectReader br(r.get("bump"), r.at("bump"), file.string());
    BumpMap b;
    if (!br.has("file")) br.fail(br.path(), "missing key \"file\"");
    b.file = resolve(file, path_string(br, "file"));
    if (const auto why = file_problem(b.file); !why.empty()) br.fail(br.at("file"), why);
    const std::string v = br.string("variant", "height");
    if (v == "height")
      b.variant = BumpVariant::height;
    else if (v == "normal-map")
      b.variant = BumpVariant::normal_map;
    else if (v == "pov")
      b.variant = BumpVariant::pov;
    else
      br.fail(br.at("variant"), "expected \"height\", \"normal-map\" or \"pov\", got \"" + v + "\"");
    b.strength = br.number("strength", b.variant == BumpVariant::pov ? 0.5 : 1.0);
    b.filter = parse_filter(br, "filter");
    br.finish();
    m.bump = b;
  }
  r.finish();
  return m;
}

// Placed meshes by their object's JSON: a scene placing one mesh the same
// way many times loads and prepares it once (400 placements of a 69,666-
// triangle mesh took 21.6 s and 3.5 GB). Objects
// share the TriangleSet; the tracer prepares each set once.
using PlacedMeshes = std::map<std::string, std::shared_ptr<TriangleSet>>;

Object parse_object(const json& j, const std::string& path, const std::filesystem::path& file, PlacedMeshes& placed) {
  ObjectReader r(j, path, file.string());
  Object o;
  int kinds = int(r.has("sphere")) + int(r.has("plane")) + int(r.has("triangle")) + int(r.has("mesh"));
  if (kinds != 1) r.fail(path, "an object needs exactly one of \"sphere\", \"plane\", \"triangle\", \"mesh\"");
  if (r.has("sphere")) {
    o.kind = Object::Kind::sphere;
    ObjectReader s(r.get("sphere"), r.at("sphere"), file.string());
    o.sphere.center = s.vec3("center", o.sphere.center);
    o.sphere.radius = s.positive("radius", o.sphere.radius);
    s.finish();
  } else if (r.has("plane")) {
    o.kind = Object::Kind::plane;
    ObjectReader p(r.get("plane"), r.at("plane"), file.string());
    Vec3d n = p.vec3("normal", o.plane.normal);
    const double len = length(n);
    if (!(len > 0)) p.fail(p.at("normal"), "the normal must not be zero");
    // POV-Ray scales the offset with the normal when normalising it.
    o.plane.normal = n / len;
    o.plane.offset = p.number("offset", 0) / len;
    p.finish();
  } else if (r.has("triangle")) {
    o.kind = Object::Kind::mesh;
    const json& t = r.get("triangle");
    if (!t.is_array() || t.size() != 3) r.fail(r.at("triangle"), "expected an array of 3 vertices");
    auto set = std::make_shared<TriangleSet>();
    set->name = "triangle";
    for (int i = 0; i < 3; ++i)
      set->positions.push_back(ObjectReader::as_vec3(t[i], r.at("triangle") + "/" + std::to_string(i), r));
    set->triangles.push_back(MeshTriangle3{{0, 1, 2}, {-1, -1, -1}, {-1, -1, -1}, 0});
    o.mesh = set;
  } else {
    o.kind = Object::Kind::mesh;
    MeshPlacement place;
    const std::string mesh_path = path_string(r, "mesh");
    place.file = resolve(file, mesh_path);
    place.translate = r.vec3("translate", place.translate);
    place.scale = r.positive("scale", place.scale);
    if (r.has("rotate")) {
      const json& rot = r.get("rotate");
      if (!rot.is_array()) r.fail(r.at("rotate"), "expected an array of [axis, radians] pairs");
      for (size_t i = 0; i < rot.size(); ++i) {
        const std::string w = r.at("rotate") + "/" + std::to_string(i);
        const json& e = rot[i];
        if (!e.is_array() || e.size() != 2 || !e[0].is_string() || !e[1].is_number())
          r.fail(w, "expected [\"x\"|\"y\"|\"z\", radians]");
        const std::string axis = e[0].get<std::string>();
        if (axis != "x" && axis != "y" && axis != "z") r.fail(w, "axis must be \"x\", \"y\" or \"z\"");
        place.rotations.push_back({axis[0], e[1].get<double>()});
      }
    }
    const std::string shading = r.string("shading", "flat");
    if (shading == "flat")
      place.shading = Shading::flat;
    else if (shading == "smooth")
      place.shading = Shading::smooth;
    else
      r.fail(r.at("shading"), "expected \"flat\" or \"smooth\", got \"" + shading + "\"");
    if (r.has("material")) {
      place.material_override = parse_material(r.get("material"), r.at("material"), file);
    }
    if (const auto why = file_problem(place.file); !why.empty()) r.fail(r.at("mesh"), why);
    try {
      check_mesh_format(place.file);
    } catch (const InputError& e) {
      r.fail(r.at("mesh"), e.what());
    }
    r.finish();
    std::shared_ptr<TriangleSet>& same = placed[j.dump()];
    if (!same) same = load_placed_mesh(place);
    o.mesh = same;
    return o;
  }
  if (r.has("material")) o.material = parse_material(r.get("material"), r.at("material"), file);
  if (o.mesh) o.mesh->materials = {o.material};
  r.finish();
  return o;
}

}  // namespace

Scene parse_scene_json(const std::string& text, const std::filesystem::path& file) {
  // Line-located errors, overflowing numbers at their place, duplicate keys refused.
  const json j = parse_json_text(text, file.string());
  if (!j.is_object())
    throw InputError(located(file.string(), 0, "expected a JSON object {\"width\": ..., \"objects\": [...]}"));
  Scene s;
  s.file = file;
  ObjectReader r(j, "", file.string());
  s.width = r.integer("width", s.width, 1, 16384);
  s.height = r.integer("height", s.height, 1, 16384);
  if (r.has("camera")) {
    ObjectReader c(r.get("camera"), "/camera", file.string());
    s.camera.position = c.vec3("position", s.camera.position);
    s.camera.look_at = c.vec3("look_at", s.camera.look_at);
    s.camera.up = c.vec3("up", s.camera.up);
    s.camera.vfov = c.number("vfov", s.camera.vfov);
    if (!(s.camera.vfov > 0 && s.camera.vfov < 180)) c.fail(c.at("vfov"), "must be between 0 and 180 degrees");
    // POV-Ray's rule (parse.cpp: |look_at - location|^2 < EPSILON = 1e-10 is
    // "Camera location and look_at point must be different"): a camera 1e-6
    // from its look_at rendered here and failed there.
    if (!(dot(s.camera.look_at - s.camera.position, s.camera.look_at - s.camera.position) >= 1e-10))
      c.fail(c.at("look_at"), "must be at least 1e-5 from the position (POV-Ray refuses a nearer one)");
    if (length(cross(s.camera.look_at - s.camera.position, s.camera.up)) == 0)
      c.fail(c.at("up"), "must not be parallel to the viewing direction");
    c.finish();
    s.camera_given = true;
  }
  s.background = r.color("background", s.background);
  s.ambient_light = r.color("ambient_light", s.ambient_light);
  s.max_depth = r.integer("max_depth", s.max_depth, 1, 256);
  s.adc_bailout = r.number("adc_bailout", s.adc_bailout);
  if (s.adc_bailout < 0) r.fail(r.at("adc_bailout"), "must be 0 or more");
  if (r.has("lights")) {
    const json& ls = r.get("lights");
    if (!ls.is_array()) r.fail("/lights", "expected an array");
    for (size_t i = 0; i < ls.size(); ++i) {
      ObjectReader l(ls[i], "/lights/" + std::to_string(i), file.string());
      PointLight pl;
      if (!l.has("position")) l.fail(l.path(), "missing key \"position\"");
      pl.position = l.vec3("position", {});
      pl.color = l.color("color", pl.color);
      l.finish();
      s.lights.push_back(pl);
    }
    s.lights_given = true;
  }
  if (r.has("objects")) {
    const json& os = r.get("objects");
    if (!os.is_array()) r.fail("/objects", "expected an array");
    PlacedMeshes placed;
    for (size_t i = 0; i < os.size(); ++i)
      s.objects.push_back(parse_object(os[i], "/objects/" + std::to_string(i), file, placed));
  }
  r.finish();
  apply_content_defaults(s);
  return s;
}

Scene load_scene(const std::filesystem::path& file) {
  check_input_file(file);  // "is a directory", not "no such file"
  check_mesh_format(file);
  std::string ext = file.extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".obj") {
    Scene s;
    s.file = file;
    Object o;
    o.kind = Object::Kind::mesh;
    MeshPlacement place;
    place.file = file;
    o.mesh = load_placed_mesh(place);
    s.objects.push_back(o);
    apply_content_defaults(s);
    return s;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(located(file.string(), 0, "cannot open"));
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_scene_json(ss.str(), file);
}

std::vector<Vec3d> area_weighted_vertex_normals(const TriangleSet& set) {
  std::vector<Vec3d> vn(set.positions.size(), Vec3d{0, 0, 0});
  for (const auto& tri : set.triangles) {
    const Vec3d& a = set.positions[tri.v[0]];
    const Vec3d n = cross(set.positions[tri.v[1]] - a, set.positions[tri.v[2]] - a);
    for (int v : tri.v) vn[v] += n;
  }
  for (auto& n : vn) {
    const double len = length(n);
    if (len > 0) n = n / len;
  }
  return vn;
}

std::string cull_unsafe_reason(const TriangleSet& set) {
  // Weld: one id per distinct position (exact equality), so meshes written
  // with a vertex per face corner still count as closed.
  const std::size_t nv = set.positions.size();
  std::vector<std::uint32_t> order(nv), id(nv);
  for (std::uint32_t i = 0; i < nv; ++i) order[i] = i;
  auto key = [&](std::uint32_t i) {
    const Vec3d& p = set.positions[i];
    return std::array<double, 3>{p.x, p.y, p.z};
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::uint32_t next = 0;
  for (std::size_t k = 0; k < nv; ++k) {
    if (k > 0 && key(order[k]) != key(order[k - 1])) ++next;
    id[order[k]] = next;
  }
  std::vector<std::uint64_t> edges;  // directed, (from << 32) | to
  edges.reserve(set.triangles.size() * 3);
  for (const auto& tri : set.triangles)
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t u = id[tri.v[e]], v = id[tri.v[(e + 1) % 3]];
      if (u != v) edges.push_back(u << 32 | v);
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t k = 0; k + 1 < edges.size(); ++k)
    if (edges[k] == edges[k + 1])
      return "two triangles run along an edge in the same direction (inconsistent winding or a non-manifold edge)";
  for (const std::uint64_t e : edges)
    if (!std::binary_search(edges.begin(), edges.end(), (e & 0xffffffffu) << 32 | e >> 32))
      return "it is not closed (an edge belongs to one triangle only)";
  if (edges.empty()) return "it has no triangles with an area";
  // Signed volume (times 6) about the first vertex: positive when the
  // normals point out of the enclosed solid.
  const Vec3d o = set.positions[set.triangles[0].v[0]];
  double volume6 = 0;
  for (const auto& tri : set.triangles)
    volume6 += dot(set.positions[tri.v[0]] - o, cross(set.positions[tri.v[1]] - o, set.positions[tri.v[2]] - o));
  if (!(volume6 > 0)) return "its triangles face inward (negative signed volume)";
  return "";
}

BoundingSphere scene_bounds(const Scene& scene) {
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  bool any = false;
  for (const auto& o : scene.objects) {
    if (o.kind == Object::Kind::sphere) {
      const Vec3d r{o.sphere.radius, o.sphere.radius, o.sphere.radius};
      lo = vmin(lo, o.sphere.center - r);
      hi = vmax(hi, o.sphere.center + r);
      any = true;
    } else if (o.kind == Object::Kind::mesh) {
      for (const auto& p : o.mesh->positions) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
        any = true;
      }
    }
  }
  if (!any) return {{0, 0, 0}, 1};
  // Centre of the box, radius reaching the farthest point of any object.
  BoundingSphere b{(lo + hi) * 0.5, 0};
  for (const auto& o : scene.objects) {
    if (o.kind == Object::Kind::sphere)
      b.radius = std::max(b.radius, length(o.sphere.center - b.center) + o.sphere.radius);
    else if (o.kind == Object::Kind::mesh)
      for (const auto& p : o.mesh->positions) b.radius = std::max(b.radius, length(p - b.center));
  }
  if (!(b.radius > 0)) b.radius = 1;
  return b;
}

void apply_content_defaults(Scene& s) {
  if (!s.camera_given) {
    // Frame the bounding sphere: it fits the vertical field of view with a
    // 10% margin, seen from +z (towards -z), y up.
    const BoundingSphere b = scene_bounds(s);
    const double half = s.camera.vfov * 0.5 * M_PI / 180.0;
    const double dist = 1.1 * b.radius / std::sin(half);
    s.camera.look_at = b.center;
    s.camera.position = b.center + Vec3d{0, 0, dist};
    s.camera.up = {0, 1, 0};
  }
  if (!s.lights_given) s.lights = {PointLight{s.camera.position, {1, 1, 1}}};
}

}  // namespace ra
