#include "golden.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "golden_project.h"
#include "their_image.h"
#include "io/atomic_file.h"
#include "errors.h"
#include "io/input_file.h"
#include "io/json_input.h"
#include "registry.h"
#include "render.h"
#include "scene/scene_mesh.h"

namespace ra {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string fnv1a64_hex(const std::string& bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string read_bytes(const fs::path& p) {
  check_input_file(p);  // what it is if not a file; an output naming it is refused
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(located(p.string(), 0, "cannot read"));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A path as the manifest records it: relative to the repository, or
// "${cache}/..." for the cache (whose place differs between machines).
std::string relative_to(const fs::path& p, const fs::path& root) {
  const fs::path a = fs::weakly_canonical(p), r = fs::weakly_canonical(root);
  if (const auto cache = expand_cache_prefix("${cache}/x")) {
    const fs::path in_cache = a.lexically_relative(fs::weakly_canonical(cache->parent_path()));
    if (!in_cache.empty() && *in_cache.begin() != "..") return "${cache}/" + in_cache.generic_string();
  }
  const fs::path rel = a.lexically_relative(r);
  if (rel.empty() || *rel.begin() == "..") return a.generic_string();
  return rel.generic_string();
}

// The mtllib files an OBJ names (resolved beside it), those that exist.
std::vector<fs::path> mtllibs(const fs::path& obj) {
  std::vector<fs::path> out;
  std::ifstream in(obj);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word) || word != "mtllib") continue;
    for (std::string f; ls >> f;)
      if (fs::exists(obj.parent_path() / f)) out.push_back(obj.parent_path() / f);
  }
  return out;
}

// The settings a golden is rendered with, as recorded in the manifest.
// The render defaults (RenderOptions), as recorded in the manifest.
json default_settings() {
  const RenderOptions o;
  return {{"triangle_method", o.triangle_method},
          {"sphere_method", o.sphere_method},
          {"precision", o.use_double ? "double" : "float"},
          {"self_intersection", self_intersection_name(o.self_intersection)},
          {"accel", accel_name(o.accel)},
          {"spp", o.samples_per_axis * o.samples_per_axis}};
}

RenderOptions options_from(const json& s) {
  RenderOptions o;
  o.triangle_method = s.value("triangle_method", o.triangle_method);
  o.sphere_method = s.value("sphere_method", o.sphere_method);
  o.use_double = s.value("precision", std::string("double")) == "double";
  if (auto si = parse_self_intersection(s.value("self_intersection", std::string("pov")))) o.self_intersection = *si;
  if (auto a = parse_accel(s.value("accel", std::string("none")))) o.accel = *a;
  const int spp = s.value("spp", 1);
  o.samples_per_axis = std::max(1, int(std::lround(std::sqrt(double(spp)))));
  o.progress = false;
  return o;
}

json to_json(const GoldenEntry& e) {
  json j = {{"name", e.name},     {"scene", e.scene}, {"image", e.image},       {"width", e.width},
            {"height", e.height}, {"bits", e.bits},   {"settings", e.settings}, {"inputs_hash", e.inputs_hash},
            {"inputs", e.inputs}};
  // Written only when set, so the defaults' manifests stay as they were.
  if (e.max_side != kGoldenMaxSize) j["max_side"] = e.max_side;
  if (!e.tolerance.identical())
    j["tolerance"] = {{"max_levels", e.tolerance.max_levels}, {"max_pixels", e.tolerance.max_pixels}};
  return j;
}

// A JSON value as the file has it, for a message: numbers and booleans as
// written (9223372036854775808, not the -9223372036854775808 a cast gives),
// anything else by its type.
std::string shown(const json& v) {
  if (v.is_number() || v.is_boolean()) return v.dump();
  return v.type_name();
}

// One manifest entry, read strictly as scene files are
// ("spp": 0 put at the wrong level, a misspelt "widht" and "width":
// 1.5 read as 1 all passed): an unknown key, a value of the wrong type or
// out of range is an error at its JSON path, quoting the file's value.
// `fail(path, what)` throws.
template <class Fail>
GoldenEntry entry_from(const json& j, const std::string& at, const Fail& fail) {
  static const std::set<std::string> known = {"name",     "scene",       "image",  "width",    "height",   "bits",
                                              "settings", "inputs_hash", "inputs", "max_side", "tolerance"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!known.count(it.key())) fail(at + "/" + it.key(), "unknown key");
  auto need = [&](const char* key) -> const json& {
    if (!j.contains(key)) fail(at, std::string("needs \"") + key + "\"");
    return j.at(key);
  };
  auto string = [&](const json& v, const std::string& where) {
    if (!v.is_string()) fail(where, "expected a string, got " + shown(v));
    return v.get<std::string>();
  };
  auto integer = [&](const json& v, const std::string& where, long long lo, long long hi, const char* unit) {
    if (!v.is_number_integer()) fail(where, "expected an integer, got " + shown(v));
    const bool in = v.is_number_unsigned() ? v.get<unsigned long long>() <= static_cast<unsigned long long>(hi) &&
                                                 static_cast<long long>(v.get<unsigned long long>()) >= lo
                                           : v.get<long long>() >= lo && v.get<long long>() <= hi;
    if (!in) fail(where, v.dump() + " is not " + std::to_string(lo) + " to " + std::to_string(hi) + unit);
    return int(v.get<long long>());
  };
  GoldenEntry e;
  e.name = string(need("name"), at + "/name");
  e.scene = string(need("scene"), at + "/scene");
  e.image = string(need("image"), at + "/image");
  e.width = integer(need("width"), at + "/width", 1, kMaxImageSide, " pixels");
  e.height = integer(need("height"), at + "/height", 1, kMaxImageSide, " pixels");
  if (j.contains("bits")) {
    const json& b = j.at("bits");
    if (b != 8 && b != 16) fail(at + "/bits", "must be 8 or 16, got " + shown(b));
    e.bits = b.get<int>();
  }
  if (j.contains("max_side")) e.max_side = integer(j.at("max_side"), at + "/max_side", 1, kMaxImageSide, " pixels");
  if (j.contains("tolerance")) {
    const json& t = j.at("tolerance");
    if (!t.is_object())
      fail(at + "/tolerance", "expected an object {\"max_levels\": L, \"max_pixels\": P}, got " + shown(t));
    for (auto it = t.begin(); it != t.end(); ++it)
      if (it.key() != "max_levels" && it.key() != "max_pixels") fail(at + "/tolerance/" + it.key(), "unknown key");
    if (t.contains("max_levels"))
      e.tolerance.max_levels = integer(t.at("max_levels"), at + "/tolerance/max_levels", 0, 65535, " levels");
    if (t.contains("max_pixels"))
      e.tolerance.max_pixels =
          integer(t.at("max_pixels"), at + "/tolerance/max_pixels", 0, kMaxImageSide * kMaxImageSide / 4, " pixels");
  }
  e.settings = default_settings();
  if (j.contains("settings")) {
    // Values are checked by settings_problem() (as render checks its flags);
    // a key it does not know is an error here, not ignored.
    const json& s = j.at("settings");
    if (s.is_object())
      for (auto it = s.begin(); it != s.end(); ++it)
        if (!e.settings.contains(it.key())) fail(at + "/settings/" + it.key(), "unknown key");
    e.settings = s;
  }
  e.inputs_hash = string(need("inputs_hash"), at + "/inputs_hash");
  if (j.contains("inputs")) {
    const json& in = j.at("inputs");
    if (!in.is_object()) fail(at + "/inputs", "expected an object, got " + shown(in));
    for (auto it = in.begin(); it != in.end(); ++it)
      e.inputs[it.key()] = string(it.value(), at + "/inputs/" + it.key());
  }
  return e;
}

// A relative path that stays under the root: no "..", not absolute, not empty.
bool inside_root(const std::string& p) {
  const fs::path path(p);
  if (p.empty() || path.is_absolute()) return false;
  for (const auto& part : path)
    if (part == "..") return false;
  return true;
}

// What the manifest's values must be before anything is rendered or
// written (a width of -8 was "cannot create std::vector larger than
// max_size()", 100000 a bare bad_alloc; a name of "../x" put the diff image
// outside --diff-dir).
std::string entry_problem(const GoldenEntry& e) {
  if (!inside_root(e.name)) return "name \"" + e.name + "\" must be a relative path without \"..\"";
  if (!inside_root(e.scene)) return "scene \"" + e.scene + "\" must be a relative path under the root without \"..\"";
  if (!inside_root(e.image)) return "image \"" + e.image + "\" must be a relative path under the root without \"..\"";
  if (e.width < 1 || e.height < 1 || e.width > int(kMaxImageSide) || e.height > int(kMaxImageSide))
    return "size " + std::to_string(e.width) + "x" + std::to_string(e.height) + " is not 1 to " +
           std::to_string(kMaxImageSide) + " pixels a side";
  if (e.bits != 8 && e.bits != 16) return "bits must be 8 or 16, got " + std::to_string(e.bits);
  return "";
}

// The render settings a golden records, checked as `render` checks its
// flags (a manifest's spp of 2 was rendered at 1, a wrong method name
// failed later naming no manifest): "" or the problem; *key names the
// setting.
std::string settings_problem(const json& s, std::string* key) {
  if (!s.is_object()) return *key = "", "settings must be an object";
  auto text = [&](const char* k, std::string& v) {
    *key = k;
    if (!s.contains(k)) return true;
    if (!s.at(k).is_string()) return false;
    v = s.at(k).get<std::string>();
    return true;
  };
  std::string v;
  for (auto [k, kind] : {std::pair{"triangle_method", Kind::triangle}, {"sphere_method", Kind::sphere}}) {
    v.clear();
    if (!text(k, v)) return "expected a string";
    const Method* m = v.empty() ? nullptr : find_method(v);
    if (s.contains(k) && (!m || m->kind != kind))
      return "unknown " + std::string(kind == Kind::triangle ? "triangle" : "sphere") + " method \"" + v +
             "\"; valid: " + method_names(kind);
  }
  v.clear();
  if (!text("precision", v)) return "expected a string";
  if (s.contains("precision") && v != "float" && v != "double")
    return "precision must be float or double, got \"" + v + "\"";
  v.clear();
  if (!text("self_intersection", v)) return "expected a string";
  if (s.contains("self_intersection") && !parse_self_intersection(v)) return "unknown self_intersection \"" + v + "\"";
  v.clear();
  if (!text("accel", v)) return "expected a string";
  if (s.contains("accel") && !parse_accel(v)) return "unknown accel \"" + v + "\"";
  *key = "spp";
  if (s.contains("spp")) {
    const json& n = s.at("spp");
    if (!n.is_number_integer()) return "spp must be an integer";
    const long long spp = n.get<long long>();
    bool square = false;
    for (long long a = 1; a <= 16; ++a) square = square || a * a == spp;
    if (!square)
      return "spp must be a square number of samples per pixel (1, 4, 9, ... 256) as for render --spp, got " +
             std::to_string(spp);
  }
  return "";
}

// Which inputs differ between what was blessed and what is there now.
std::string changed_inputs(const std::map<std::string, std::string>& then,
                           const std::map<std::string, std::string>& now) {
  std::string out;
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : ", ") + s; };
  for (const auto& [f, h] : now) {
    auto it = then.find(f);
    if (it == then.end())
      add(f + " (new)");
    else if (it->second != h)
      add(f + " (changed)");
  }
  for (const auto& [f, h] : then)
    if (!now.count(f)) add(f + " (no longer used)");
  return out;
}

void golden_size(int w, int h, int max_side, int& gw, int& gh) {
  const double s = std::min(1.0, double(max_side) / double(std::max(w, h)));
  gw = std::max(1, int(std::lround(w * s)));
  gh = std::max(1, int(std::lround(h * s)));
}

}  // namespace

std::map<std::string, std::string> scene_inputs(const Scene& scene, const fs::path& root) {
  std::set<fs::path> files{scene.file};
  auto material_files = [&](const Material& m) {
    if (m.texture) files.insert(m.texture->file);
    if (m.bump) files.insert(m.bump->file);
  };
  for (const auto& o : scene.objects) {
    material_files(o.material);
    if (o.kind != Object::Kind::mesh || !o.mesh) continue;
    for (const auto& m : o.mesh->materials) material_files(m);
    const fs::path obj = o.mesh->name;
    std::error_code ec;
    if (o.mesh->name != "triangle" && fs::is_regular_file(obj, ec)) {
      files.insert(obj);
      for (const auto& mtl : mtllibs(obj)) files.insert(mtl);
    }
  }
  std::map<std::string, std::string> out;
  for (const auto& f : files) out[relative_to(f, root)] = fnv1a64_hex(read_bytes(f));
  return out;
}

std::vector<fs::path> missing_cache_inputs(const fs::path& scene_file) {
  std::vector<fs::path> out;
  std::function<void(const json&)> walk = [&](const json& j) {
    if (j.is_string()) {
      if (auto p = expand_cache_prefix(j.get<std::string>()); p && !fs::exists(*p)) out.push_back(*p);
    } else if (j.is_structured()) {
      for (const auto& e : j) walk(e);
    }
  };
  try {
    walk(json::parse(read_bytes(scene_file)));
  } catch (const json::exception&) {
    // load_scene reports a malformed scene with its line.
  }
  return out;
}

std::string combined_hash(const std::map<std::string, std::string>& inputs) {
  std::string all;
  for (const auto& [f, h] : inputs) all += f + '\0' + h + '\n';
  return "fnv1a64:" + fnv1a64_hex(all);
}

GoldenSet::GoldenSet(fs::path root) : root_(std::move(root)) {
  const fs::path m = root_ / "golden" / "manifest.json";
  if (!fs::exists(m)) return;
  JsonLines lines;                                    // every error names its line
  const json j = read_json_file(m.string(), &lines);  // FILE:LINE errors, duplicate keys refused
  try {
    if (!j.is_object() || !j.contains("goldens") || !j.at("goldens").is_array())
      throw InputError(located(m.string(), lines.at("/goldens"), "expected an object with a \"goldens\" array"));
    // What a reader would otherwise take on trust: a key
    // of no meaning, an entry whose scene is another's, two entries
    // sharing one image (each then checked against the other's render).
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key() != "about" && it.key() != "goldens")
        throw InputError(located(m.string(), lines.at("/" + it.key()), "/" + it.key() + ": unknown key"));
    std::map<std::string, std::string> image_of;  // image -> the golden that has it
    const json& all = j.at("goldens");
    for (std::size_t i = 0; i < all.size(); ++i) {
      const std::string ptr = "/goldens/" + std::to_string(i);
      const std::string at = located(m.string(), lines.at(ptr), ptr);
      if (!all[i].is_object()) throw InputError(at + ": expected an object");
      const GoldenEntry g = entry_from(all[i], ptr, [&](const std::string& where, const std::string& what) {
        throw InputError(located(m.string(), lines.at(where), where + ": " + what));
      });
      if (const std::string why = entry_problem(g); !why.empty()) throw InputError(at + ": " + why);
      std::string key;
      if (const std::string why = settings_problem(g.settings, &key); !why.empty()) {
        const std::string sp = ptr + "/settings" + (key.empty() ? "" : "/" + key);
        throw InputError(located(m.string(), lines.at(sp), sp + ": " + why));
      }
      if (entries_.count(g.name)) throw InputError(at + ": golden \"" + g.name + "\" listed twice");
      if (g.scene != "scenes/" + g.name + ".json")
        throw InputError(at + ": scene \"" + g.scene + "\" is not this golden's, scenes/" + g.name + ".json");
      if (const auto [it, fresh] = image_of.emplace(g.image, g.name); !fresh)
        throw InputError(at + ": image \"" + g.image + "\" is golden \"" + it->second + "\"'s too");
      entries_[g.name] = g;
    }
  } catch (const json::exception& e) {
    throw InputError(m.string() + ": " + json_error_text(e));
  }
}

std::vector<std::filesystem::path> GoldenSet::inputs_of(const std::string& name) const {
  std::vector<fs::path> out{root_ / "scenes" / (name + ".json")};
  if (auto it = entries_.find(name); it != entries_.end()) out.push_back(root_ / it->second.image);
  return out;
}

std::vector<std::string> GoldenSet::all_names() const {
  std::set<std::string> names;
  if (fs::is_directory(root_ / "scenes"))
    for (const auto& e : fs::directory_iterator(root_ / "scenes"))
      if (e.path().extension() == ".json") names.insert(e.path().stem().string());
  for (const auto& [n, e] : entries_) names.insert(n);
  return {names.begin(), names.end()};
}

namespace {

Image render_golden(const fs::path& scene_file, int w, int h, const json& settings, Scene* loaded = nullptr) {
  Scene s = load_scene(scene_file);
  const int own_w = s.width, own_h = s.height;
  s.width = w;
  s.height = h;
  const Image img = render(s, options_from(settings));
  if (loaded) {
    *loaded = std::move(s);
    loaded->width = own_w;  // the scene's own size, for coordinates in its pixels
    loaded->height = own_h;
  }
  return img;
}

}  // namespace

std::vector<fs::path> GoldenSet::diff_outputs(const std::string& name, const fs::path& diff_dir) {
  return {diff_dir / (name + ".diff.png"), diff_dir / (name + ".png")};
}

std::string GoldenSet::bless_command(const std::string& name) const {
  std::error_code ec;
  // The name as typed when it is one plain word; the root always quoted.
  const bool plain = !name.empty() && name.find_first_not_of(
                                          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                          "0123456789._/+-") == std::string::npos;
  return "rayaudit golden bless " + (plain ? name : shell_quoted(name)) + " --root " +
         shell_quoted(fs::absolute(root_, ec).lexically_normal().string());
}

GoldenSet::Reference GoldenSet::reference_of(const std::string& name) const {
  auto it = entries_.find(name);
  if (it == entries_.end())
    throw InputError(
        located((root_ / "golden" / "manifest.json").string(), 0,
                "no golden \"" + name + "\" to judge an image against; record one with `" + bless_command(name) + "`"));
  return {it->second.width, it->second.height, it->second.bits, it->second.image};
}

std::vector<fs::path> GoldenSet::images() const {
  std::vector<fs::path> out;
  for (const auto& [n, e] : entries_) out.push_back(root_ / e.image);
  return out;
}

namespace {

// The scene pixel holding the centre of golden pixel g, the golden being n
// pixels across a scene of N: the golden is the scene rendered at n / N of
// its size, so its pixel centres fall at (g + 0.5) N / n scene pixels.
int scene_pixel(int g, int n, int N) { return std::min(N - 1, int(std::floor((g + 0.5) * double(N) / double(n)))); }

// The verdict of `c` under tolerance `t`: pass, and what it found.
std::pair<bool, std::string> judge_golden(const ImageComparison& c, const GoldenTolerance& t) {
  int worst = 0;
  for (const auto& d : c.differences) worst = std::max(worst, d.levels);
  const long n = long(c.differences.size());
  const bool pass = n <= t.max_pixels && worst <= t.max_levels;
  std::string says = std::to_string(n) + " pixels differ (at most " + std::to_string(t.max_pixels) +
                     " allowed), by at most " + std::to_string(worst) + " levels (at most " +
                     std::to_string(t.max_levels) + " allowed)";
  return {pass, says};
}

}  // namespace

GoldenSet::Result GoldenSet::check(const std::string& name, const fs::path& diff_dir,
                                   const std::function<void(const fs::path&)>& before_write,
                                   const fs::path* theirs) const {
  const fs::path scene_file = root_ / "scenes" / (name + ".json");
  Result r;
  r.detail = {{"name", name}, {"scene", "scenes/" + name + ".json"}, {"root", fs::absolute(root_).string()}};
  if (theirs) r.detail["image"] = theirs->string();
  auto it = entries_.find(name);
  if (it == entries_.end()) {
    r.hint = bless_command(name) + " (then commit golden/)";
    r.message = name + ": no golden image for scenes/" + name + ".json; render and record one with `" + r.hint + "`";
    r.detail["hint"] = r.hint;
    return r;
  }
  const GoldenEntry& g = it->second;
  r.detail["golden"] = g.image;
  if (!fs::exists(scene_file)) {
    r.hint = bless_command(name);
    r.message = name + ": the scene " + g.scene + " is gone but its golden remains; `" + r.hint + "` removes it";
    r.detail["hint"] = r.hint;
    return r;
  }
  // The golden first: its size, bounded by its file, is checked against the
  // manifest's before a render of the manifest's size (a width of 16384 with
  // an 8x8 golden rendered 3.3 GB first).
  const Image golden = read_image(root_ / g.image);
  if (golden.width != g.width || golden.height != g.height) {
    r.hint = bless_command(name);
    r.message = name + ": " + g.image + " is " + std::to_string(golden.width) + "x" + std::to_string(golden.height) +
                " but the manifest says " + std::to_string(g.width) + "x" + std::to_string(g.height) +
                "; re-bless it: `" + r.hint + "`";
    r.detail["hint"] = r.hint;
    return r;
  }
  Scene scene;
  Image candidate;
  if (theirs) {
    candidate = read_their_image(*theirs, {g.width, g.height, g.bits, g.image, ""});
    scene = load_scene(scene_file);
  } else {
    candidate = render_golden(scene_file, g.width, g.height, g.settings, &scene);
  }
  const int sw = scene.width, sh = scene.height;  // the scene's own size (render_golden keeps it)
  const auto inputs = scene_inputs(scene, root_);
  const std::string changed = combined_hash(inputs) == g.inputs_hash ? "" : changed_inputs(g.inputs, inputs);
  ImageComparison c = compare_images(candidate, golden, g.bits);
  const auto [within, verdict] = judge_golden(c, g.tolerance);

  // compare --json's fields, coordinates in scene pixels.
  nlohmann::json& d = r.detail;
  const nlohmann::json cj = to_json(c);
  for (auto jt = cj.begin(); jt != cj.end(); ++jt) d[jt.key()] = jt.value();
  d["scene_width"] = sw;
  d["scene_height"] = sh;
  auto sx = [&](int x) { return scene_pixel(x, g.width, sw); };
  auto sy = [&](int y) { return scene_pixel(y, g.height, sh); };
  d["max_error_pixel"] = {
      {"x", sx(c.max_x)}, {"y", sy(c.max_y)}, {"golden_x", c.max_x}, {"golden_y", c.max_y}, {"channel", c.max_channel}};
  nlohmann::json diffs = nlohmann::json::array();
  for (const auto& p : c.differences)
    diffs.push_back({{"x", sx(p.x)}, {"y", sy(p.y)}, {"golden_x", p.x}, {"golden_y", p.y}, {"levels", p.levels}});
  d["differences"] = diffs;
  d["tolerance"] = {{"max_levels", g.tolerance.max_levels}, {"max_pixels", g.tolerance.max_pixels}};
  d["tolerance_file"] = (root_ / "golden" / "manifest.json").string();
  d["within_tolerance"] = within;
  d["verdict"] = nlohmann::json::array({verdict});
  d["inputs_changed"] = changed;

  const std::string size = std::to_string(g.width) + "x" + std::to_string(g.height);
  const std::string what = theirs ? theirs->string() : std::string("this render");
  if (within && changed.empty()) {
    r.pass = true;
    r.message = name + ": " + (theirs ? what + " " : "") +
                (c.identical() ? "identical to " + g.image + " (" + size + ")"
                               : "within the tolerance of " + g.image + " (" + size + "): " + verdict);
    return r;
  }
  if (c.identical()) {
    r.hint = bless_command(name);
    r.message = name + ": the image is identical to " + g.image + ", but the inputs changed since it was blessed (" +
                changed + "): the golden is stale; record them with `" + r.hint + "`";
    d["hint"] = r.hint;
    return r;
  }
  std::error_code ec;
  const fs::path diff = diff_dir / (name + ".diff.png"), mine = diff_dir / (name + ".png");
  fs::create_directories(diff.parent_path(), ec);  // names may hold a folder: corpus/ladder-10-box
  if (before_write) before_write(diff);
  write_image(diff, difference_image(candidate, golden, g.bits));
  d["diff_image"] = diff.string();
  d["diff_key"] = difference_key_json();
  if (!theirs) {
    if (before_write) before_write(mine);
    write_image(mine, candidate);
    d["render_image"] = mine.string();
  }
  // The summary's lines, the maximum's pixel in scene pixels.
  ImageComparison shown = c;
  shown.max_x = sx(c.max_x);
  shown.max_y = sy(c.max_y);
  r.message =
      name + ": " + (theirs ? what + " " : "") + (within ? "matches " : "differs from ") + g.image + " (" + size +
      (g.width == sw && g.height == sh ? ""
                                       : ", the scene's " + std::to_string(sw) + "x" + std::to_string(sh) + " scaled") +
      "): " + verdict + "\n" + summary(shown);
  r.message += "coordinates are scene pixels (of " + std::to_string(sw) + "x" + std::to_string(sh) + ")";
  if (g.width != sw || g.height != sh) r.message += "; the golden and diff images are " + size;
  r.message += "\nfirst differences:";
  for (std::size_t i = 0; i < c.differences.size() && i < 8; ++i)
    r.message += " (" + std::to_string(sx(c.differences[i].x)) + ", " + std::to_string(sy(c.differences[i].y)) + ") " +
                 std::to_string(c.differences[i].levels) + (c.differences[i].levels == 1 ? " level" : " levels") +
                 (i + 1 < c.differences.size() && i < 7 ? ";" : "");
  if (c.differences.size() > 8) r.message += " ...";
  r.message += "\ndiff image: " + diff.string() + "\n" + difference_key_text();
  if (!theirs) r.message += "this render: " + mine.string() + "\n";
  if (!changed.empty()) {
    r.hint = bless_command(name);
    r.message += "the inputs changed since the golden was blessed (" + changed + "); if the new image is intended, `" +
                 r.hint + "`";
    d["hint"] = r.hint;
  } else if (theirs) {
    r.message += "the scene's inputs are unchanged since the golden was blessed: the difference is the image's";
  } else {
    r.message += "the inputs are unchanged since the golden was blessed: the renderer's output changed";
  }
  return r;
}

std::string GoldenSet::bless(const std::string& name, OutputBatch* batch) {
  const fs::path scene_file = root_ / "scenes" / (name + ".json");
  if (!fs::exists(scene_file)) {
    auto it = entries_.find(name);
    if (it == entries_.end()) throw InputError(scene_file.string() + ": no such scene");
    to_remove_.push_back(root_ / it->second.image);  // when the manifest is saved
    entries_.erase(it);
    removed_ = true;
    return name + ": removed (its scene is gone)";
  }
  GoldenEntry g;
  g.name = name;
  g.scene = "scenes/" + name + ".json";
  g.image = "golden/" + name + ".png";
  g.settings = default_settings();
  // A size and tolerance set in the manifest for this scene stay.
  if (auto was = entries_.find(name); was != entries_.end()) {
    g.max_side = was->second.max_side;
    g.tolerance = was->second.tolerance;
  }
  Scene scene = load_scene(scene_file);
  golden_size(scene.width, scene.height, g.max_side, g.width, g.height);
  const Image img = render_golden(scene_file, g.width, g.height, g.settings, &scene);
  g.inputs = scene_inputs(scene, root_);
  g.inputs_hash = combined_hash(g.inputs);

  std::string what;
  auto old = entries_.find(name);
  const bool had_image = old != entries_.end() && fs::exists(root_ / old->second.image);
  bool write_png = true;
  if (!had_image) {
    what = name + ": new golden " + g.image + " (" + std::to_string(g.width) + "x" + std::to_string(g.height) + ")";
  } else {
    const Image prev = read_image(root_ / old->second.image);
    if (prev.width == g.width && prev.height == g.height) {
      const ImageComparison c = compare_images(img, prev, g.bits);
      if (c.identical()) {
        write_png = false;
        what = name + ": image unchanged";
      } else {
        what = name + ": image changed: " + std::to_string(c.differences.size()) + " of " + std::to_string(c.pixels) +
               " pixels differ, max " + std::to_string(long(std::lround(c.max_error * 255))) + "/255";
      }
    } else {
      what = name + ": size changed to " + std::to_string(g.width) + "x" + std::to_string(g.height);
    }
    if (old->second.settings != g.settings)
      what += "; render settings changed from " + old->second.settings.dump() + " to " + g.settings.dump();
    if (old->second.inputs_hash != g.inputs_hash)
      what += "; inputs changed: " + changed_inputs(old->second.inputs, g.inputs);
    else
      what += "; inputs unchanged";
  }
  std::error_code ec;
  fs::create_directories((root_ / g.image).parent_path(), ec);
  if (write_png) {
    if (batch) batch->add_replacement(root_ / g.image);
    write_image(root_ / g.image, img, {8, false});
  }
  entries_[name] = g;
  return what;
}

void GoldenSet::save(OutputBatch* batch) const {
  json all = json::array();
  for (const auto& [n, e] : entries_) all.push_back(to_json(e));
  json j = {{"about",
             "Golden images of scenes/*.json, rendered by rayaudit itself; checked by "
             "`rayaudit golden check` (ctest label golden), rewritten only by `rayaudit golden bless`. "
             "Each is its scene rendered at most \"max_side\" pixels on the long side (default 160) and "
             "must match within \"tolerance\" {\"max_levels\": L, \"max_pixels\": P} (default "
             "identical); both may be set per golden."},
            {"goldens", all}};
  std::error_code ec;
  fs::create_directories(root_ / "golden", ec);
  if (batch) batch->add_replacement(root_ / "golden" / "manifest.json");
  write_text_atomically(root_ / "golden" / "manifest.json",
                        j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (batch) batch->commit();  // the images and the manifest together
  for (const auto& f : to_remove_) fs::remove(f, ec);
}

}  // namespace ra
