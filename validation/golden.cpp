#include "golden.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

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
  return {{"name", e.name},     {"scene", e.scene},       {"image", e.image},   {"width", e.width},
          {"height", e.height}, {"bits", e.bits},         {"settings", e.settings},
          {"inputs_hash", e.inputs_hash},                 {"inputs", e.inputs}};
}

// A JSON value as the file has it, for a message: numbers and booleans as
// written (9223372036854775808, not the -9223372036854775808 a cast gives),
// anything else by its type.
std::string shown(const json& v) {
  if (v.is_number() || v.is_boolean()) return v.dump();
  return v.type_name();
}

// One manifest entry, read strictly as scene files are (issue 15's second
// pass: "spp": 0 put at the wrong level, a misspelt "widht" and "width":
// 1.5 read as 1 all passed): an unknown key, a value of the wrong type or
// out of range is an error at its JSON path, quoting the file's value.
// `fail(path, what)` throws.
template <class Fail>
GoldenEntry entry_from(const json& j, const std::string& at, const Fail& fail) {
  static const std::set<std::string> known = {"name",   "scene", "image",       "width",  "height",
                                              "bits",   "settings", "inputs_hash", "inputs"};
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
  e.settings = default_settings();
  if (j.contains("settings")) {
    const json& s = j.at("settings");
    const std::string sat = at + "/settings";
    if (!s.is_object()) fail(sat, "expected an object, got " + shown(s));
    for (auto it = s.begin(); it != s.end(); ++it) {
      const std::string where = sat + "/" + it.key();
      if (!e.settings.contains(it.key())) fail(where, "unknown key");
      const json& v = it.value();
      if (it.key() == "spp") {
        const int spp = integer(v, where, 1, 256, "");
        const int n = int(std::lround(std::sqrt(double(spp))));
        if (n * n != spp) fail(where, "must be a square number of samples (1, 4, 9, ...), got " + v.dump());
      } else {
        const std::string name = string(v, where);
        bool ok = true;
        if (it.key() == "triangle_method") ok = find_method(name) && find_method(name)->kind == Kind::triangle;
        else if (it.key() == "sphere_method") ok = find_method(name) && find_method(name)->kind == Kind::sphere;
        else if (it.key() == "precision") ok = name == "float" || name == "double";
        else if (it.key() == "self_intersection") ok = parse_self_intersection(name).has_value();
        else if (it.key() == "accel") ok = parse_accel(name).has_value();
        if (!ok) fail(where, "\"" + name + "\" is not a valid value");
      }
      e.settings[it.key()] = v;
    }
  }
  e.inputs_hash = string(need("inputs_hash"), at + "/inputs_hash");
  if (j.contains("inputs")) {
    const json& in = j.at("inputs");
    if (!in.is_object()) fail(at + "/inputs", "expected an object, got " + shown(in));
    for (auto it = in.begin(); it != in.end(); ++it) e.inputs[it.key()] = string(it.value(), at + "/inputs/" + it.key());
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
// outside --diff-dir: issue 15's second pass).
std::string entry_problem(const GoldenEntry& e) {
  if (!inside_root(e.name)) return "name \"" + e.name + "\" must be a relative path without \"..\"";
  if (!inside_root(e.scene)) return "scene \"" + e.scene + "\" must be a relative path under the root without \"..\"";
  if (!inside_root(e.image)) return "image \"" + e.image + "\" must be a relative path under the root without \"..\"";
  return "";
}

// Which inputs differ between what was blessed and what is there now.
std::string changed_inputs(const std::map<std::string, std::string>& then,
                           const std::map<std::string, std::string>& now) {
  std::string out;
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : ", ") + s; };
  for (const auto& [f, h] : now) {
    auto it = then.find(f);
    if (it == then.end()) add(f + " (new)");
    else if (it->second != h) add(f + " (changed)");
  }
  for (const auto& [f, h] : then)
    if (!now.count(f)) add(f + " (no longer used)");
  return out;
}

void golden_size(int w, int h, int& gw, int& gh) {
  const double s = std::min(1.0, double(kGoldenMaxSize) / double(std::max(w, h)));
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
  const json j = read_json_file(m.string());  // FILE:LINE errors, duplicate keys refused
  try {
    if (!j.is_object() || !j.contains("goldens") || !j.at("goldens").is_array())
      throw InputError(m.string() + ": expected an object with a \"goldens\" array");
    const json& all = j.at("goldens");
    for (std::size_t i = 0; i < all.size(); ++i) {
      const std::string at = m.string() + ": /goldens/" + std::to_string(i);
      if (!all[i].is_object()) throw InputError(at + ": expected an object");
      const GoldenEntry g = entry_from(all[i], "/goldens/" + std::to_string(i),
                                       [&](const std::string& where, const std::string& what) {
                                         throw InputError(located(m.string(), 0, where + ": " + what));
                                       });
      if (const std::string why = entry_problem(g); !why.empty()) throw InputError(at + ": " + why);
      if (entries_.count(g.name)) throw InputError(at + ": golden \"" + g.name + "\" listed twice");
      entries_[g.name] = g;
    }
  } catch (const json::exception& e) {
    throw InputError(m.string() + ": " + json_error_text(e));
  }
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
  s.width = w;
  s.height = h;
  const Image img = render(s, options_from(settings));
  if (loaded) *loaded = std::move(s);
  return img;
}

}  // namespace

std::vector<fs::path> GoldenSet::check_inputs(const std::string& name) const {
  std::vector<fs::path> out{root_ / "scenes" / (name + ".json")};
  if (auto it = entries_.find(name); it != entries_.end()) out.push_back(root_ / it->second.image);
  return out;
}

std::vector<fs::path> GoldenSet::diff_outputs(const std::string& name, const fs::path& diff_dir) {
  return {diff_dir / (name + ".diff.png"), diff_dir / (name + ".png")};
}

GoldenSet::Result GoldenSet::check(const std::string& name, const fs::path& diff_dir,
                                   const std::function<void(const fs::path&)>& before_write) const {
  const fs::path scene_file = root_ / "scenes" / (name + ".json");
  auto it = entries_.find(name);
  if (it == entries_.end())
    return {false, name + ": no golden image for scenes/" + name + ".json; render and record one with "
                   "`rayaudit golden bless " + name + "` (then commit golden/)"};
  const GoldenEntry& g = it->second;
  if (!fs::exists(scene_file))
    return {false, name + ": the scene " + g.scene + " is gone but its golden remains; `rayaudit golden bless " + name +
                   "` removes it"};
  // The golden first: its size, bounded by its file, is checked against the
  // manifest's before a render of the manifest's size (a width of 16384 with
  // an 8x8 golden rendered 3.3 GB first; issue 15).
  const Image golden = read_image(root_ / g.image);
  if (golden.width != g.width || golden.height != g.height)
    return {false, name + ": " + g.image + " is " + std::to_string(golden.width) + "x" +
                   std::to_string(golden.height) + " but the manifest says " + std::to_string(g.width) + "x" +
                   std::to_string(g.height) + "; re-bless it"};
  Scene scene;
  const Image ours = render_golden(scene_file, g.width, g.height, g.settings, &scene);
  const auto inputs = scene_inputs(scene, root_);
  const std::string hash = combined_hash(inputs);
  const std::string changed = hash == g.inputs_hash ? "" : changed_inputs(g.inputs, inputs);
  const ImageComparison c = compare_images(ours, golden, g.bits);
  const std::string size = std::to_string(g.width) + "x" + std::to_string(g.height);
  if (c.identical() && changed.empty()) return {true, name + ": identical to " + g.image + " (" + size + ")"};
  std::string msg;
  if (c.identical()) {
    msg = name + ": the image is identical to " + g.image + ", but the inputs changed since it was blessed (" +
          changed + "): the golden is stale; record them with `rayaudit golden bless " + name + "`";
    return {false, msg};
  }
  std::error_code ec;
  const auto paths = diff_outputs(name, diff_dir);
  const fs::path &diff = paths[0], &mine = paths[1];
  fs::create_directories(diff.parent_path(), ec);  // names may hold a folder: corpus/ladder-10-box
  if (before_write) before_write(diff);
  write_image(diff, difference_image(ours, golden, g.bits));
  if (before_write) before_write(mine);
  write_image(mine, ours);
  msg = name + ": differs from " + g.image + " (" + size + ")\n" + summary(c);
  msg += "diff image: " + diff.string() + "\nthis render: " + mine.string() + "\n";
  if (!changed.empty())
    msg += "the inputs changed since the golden was blessed (" + changed +
           "); if the new image is intended, `rayaudit golden bless " + name + "`";
  else
    msg += "the inputs are unchanged since the golden was blessed: the renderer's output changed";
  return {false, msg};
}

std::string GoldenSet::bless(const std::string& name) {
  const fs::path scene_file = root_ / "scenes" / (name + ".json");
  if (!fs::exists(scene_file)) {
    auto it = entries_.find(name);
    if (it == entries_.end()) throw InputError(scene_file.string() + ": no such scene");
    pending_removal_.push_back(root_ / it->second.image);
    pending_.erase(root_ / it->second.image);
    entries_.erase(it);
    return name + ": removed (its scene is gone)";
  }
  GoldenEntry g;
  g.name = name;
  g.scene = "scenes/" + name + ".json";
  g.image = "golden/" + name + ".png";
  g.settings = default_settings();
  Scene scene = load_scene(scene_file);
  golden_size(scene.width, scene.height, g.width, g.height);
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
        what = name + ": image changed: " + std::to_string(c.differences.size()) + " of " +
               std::to_string(c.pixels) + " pixels differ, max " + std::to_string(long(std::lround(c.max_error * 255))) +
               "/255";
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
  if (write_png) pending_[root_ / g.image] = img;
  entries_[name] = g;
  return what;
}

void GoldenSet::save() {
  json all = json::array();
  for (const auto& [n, e] : entries_) all.push_back(to_json(e));
  json j = {{"about", "Golden images of scenes/*.json, rendered by rayaudit itself; checked by "
                      "`rayaudit golden check` (ctest label golden), rewritten only by `rayaudit golden bless`."},
            {"goldens", all}};
  std::error_code ec;
  fs::create_directories(root_ / "golden", ec);
  for (const auto& [path, img] : pending_) fs::create_directories(path.parent_path(), ec);
  {
    // Each image replaces the golden it was compared with (an input of
    // this run, so not declared as an output: io/file_identity.h would
    // refuse it); all renamed together after the last is written.
    OutputBatch batch({});
    const fs::path manifest = root_ / "golden" / "manifest.json";
    batch.add_replacement(manifest);
    for (const auto& [path, img] : pending_) batch.add_replacement(path);
    for (const auto& [path, img] : pending_) write_image(path, img, {8, false});
    write_text_atomically(manifest, j.dump(2) + "\n");
    batch.commit();
  }
  pending_.clear();
  for (const auto& p : pending_removal_) fs::remove(p, ec);
  pending_removal_.clear();
}

}  // namespace ra
