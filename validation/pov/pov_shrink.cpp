// Differential testing against POV-Ray: compare + explain, and the greedy
// scene shrinker of pov_shrink.h (delta debugging, one step at a time).
#include "pov_shrink.h"

#include "errors.h"
#include "images/image_compare.h"
#include "pov_runner.h"
#include "render.h"

namespace ra {

using json = nlohmann::json;

int ExplainedComparison::unexplained() const {
  int n = 0;
  for (const auto& p : pixels) n += p.cause.empty();
  return n;
}

ExplainedComparison compare_and_explain(const Scene& scene, int threads) {
  RenderOptions opt;
  opt.threads = threads;
  opt.progress = false;
  const Image ours = render(scene, opt);
  const PovRun pov = render_with_povray(scene, {});
  const ImageComparison c = compare_images(ours, pov.image, 8);
  ExplainedComparison out;
  out.differing = int(c.differences.size());
  out.pixels = explain_differences(scene, ours, pov.image, c, opt);
  return out;
}

PixelPersists unexplained_pixel_persists(const std::filesystem::path& file, int x, int y, int threads) {
  return [=](const json& j) {
    try {
      const Scene scene = parse_scene_json(j.dump(), file);
      if (x >= scene.width || y >= scene.height) return false;
      const ExplainedComparison r = compare_and_explain(scene, threads);
      for (const auto& p : r.pixels)
        if (p.x == x && p.y == y) return p.cause.empty();
      return false;
    } catch (const InputError&) {
      return false;  // a simplification that made the scene invalid
    } catch (const CheckFailed&) {
      return false;  // POV-Ray refused it
    }
  };
}

namespace {

// The scene without element i of the array at `key` (an object or a light).
json without_element(const json& s, const char* key, std::size_t i) {
  json out = s;
  out[key].erase(i);
  return out;
}

}  // namespace

std::vector<json> simplifications(const json& s) {
  std::vector<json> out;
  if (s.contains("objects"))
    for (std::size_t i = 0; i < s["objects"].size(); ++i) out.push_back(without_element(s, "objects", i));
  if (s.contains("lights"))
    for (std::size_t i = 0; i < s["lights"].size(); ++i) out.push_back(without_element(s, "lights", i));
  // Features of an object, each dropped alone (back to the default).
  static const std::vector<std::vector<std::string>> kMaterialFeatures = {
      {"reflection"}, {"phong", "phong_size"}, {"texture"}, {"ambient"}, {"diffuse"}, {"color"}};
  if (s.contains("objects"))
    for (std::size_t i = 0; i < s["objects"].size(); ++i) {
      const json& o = s["objects"][i];
      if (o.contains("material"))
        for (const auto& keys : kMaterialFeatures) {
          if (!o["material"].contains(keys[0])) continue;
          json t = s;
          for (const auto& k : keys) t["objects"][i]["material"].erase(k);
          if (t["objects"][i]["material"].empty()) t["objects"][i].erase("material");
          out.push_back(std::move(t));
        }
      if (o.contains("mesh")) {
        for (const char* k : {"material", "rotate"})
          if (o.contains(k)) {
            json t = s;
            t["objects"][i].erase(k);
            out.push_back(std::move(t));
          }
        if (o.value("shading", "flat") == "smooth") {
          json t = s;
          t["objects"][i].erase("shading");
          out.push_back(std::move(t));
        }
      }
    }
  for (const char* k : {"adc_bailout", "background", "ambient_light"})
    if (s.contains(k)) {
      json t = s;
      t.erase(k);
      out.push_back(std::move(t));
    }
  if (s.value("max_depth", 5) > 1) {
    json t = s;
    t["max_depth"] = s.value("max_depth", 5) - 1;
    out.push_back(std::move(t));
  }
  if (s.contains("lights"))
    for (std::size_t i = 0; i < s["lights"].size(); ++i)
      if (s["lights"][i].contains("color")) {
        json t = s;
        t["lights"][i].erase("color");
        out.push_back(std::move(t));
      }
  return out;
}

json shrink_scene(const json& scene, const PixelPersists& persists, int max_tries, int* tries) {
  json best = scene;
  int calls = 0;
  for (bool smaller = true; smaller && calls < max_tries;) {
    smaller = false;
    for (const json& candidate : simplifications(best)) {
      if (calls >= max_tries) break;
      ++calls;
      if (persists(candidate)) {
        best = candidate;
        smaller = true;
        break;
      }
    }
  }
  if (tries) *tries = calls;
  return best;
}

std::string readable_json(const json& j, int indent) {
  const std::string flat = j.dump();
  if (int(flat.size()) + indent <= 96 || !(j.is_object() || j.is_array()) || j.empty()) return flat;
  const std::string pad(std::size_t(indent + 2), ' ');
  std::string out = j.is_object() ? "{\n" : "[\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!first) out += ",\n";
    first = false;
    out += pad;
    if (j.is_object()) out += json(it.key()).dump() + ": ";
    out += readable_json(*it, indent + 2);
  }
  return out + "\n" + std::string(std::size_t(indent), ' ') + (j.is_object() ? "}" : "]");
}

}  // namespace ra
