#include "pov_tolerance.h"

#include <fstream>
#include <map>
#include <sstream>

#include "errors.h"
#include "image.h"
#include "io/json_input.h"

namespace ra {

std::filesystem::path pov_tolerance_path(const std::filesystem::path& scene_file) {
  return scene_file.parent_path() / "pov" / (scene_file.stem().string() + ".json");
}

PovTolerance load_pov_tolerance(const std::filesystem::path& file) {
  PovTolerance t;
  if (!std::filesystem::exists(file)) return t;
  t.file = file;
  const nlohmann::json j = read_json_file(file.string());  // FILE:LINE errors, duplicate keys refused
  try {
    if (!j.is_object()) throw InputError(file.string() + ": expected a JSON object");
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key() != "notes" && it.key() != "width" && it.key() != "height" && it.key() != "pixels" &&
          it.key() != "max_levels_16")
        throw InputError(file.string() + ": /" + it.key() + ": unknown key");
    for (const char* k : {"width", "height", "max_levels_16"})
      if (j.contains(k) && !j.at(k).is_number_integer())
        throw InputError(file.string() + ": /" + k + ": expected an integer");
    if (j.contains("notes") && !j.at("notes").is_string())
      throw InputError(file.string() + ": /notes: expected a string");
    if (j.contains("pixels") && !j.at("pixels").is_array())
      throw InputError(file.string() + ": /pixels: expected an array");
    t.notes = j.value("notes", "");
    // Sizes and pixel coordinates inside the render limit (a pixel at x -1
    // was accepted and never matched; 3e9 wrapped round as an int).
    auto side = [&](const nlohmann::json& v, const std::string& where, long long lo, long long hi) {
      // An unsigned 2^63 read as long long was quoted as -2^63: the file's own text.
      if (v.is_number_unsigned() && v.get<unsigned long long>() > (unsigned long long)hi)
        throw InputError(where + ": " + v.dump() + " is outside " + std::to_string(lo) + ".." + std::to_string(hi));
      const long long x = v.get<long long>();
      if (x < lo || x > hi)
        throw InputError(where + ": " + std::to_string(x) + " is outside " + std::to_string(lo) + ".." +
                         std::to_string(hi));
      return int(x);
    };
    const long long kSide = (long long)kMaxImageSide;
    if (j.contains("width")) t.width = side(j.at("width"), file.string() + ": /width", 1, kSide);
    if (j.contains("height")) t.height = side(j.at("height"), file.string() + ": /height", 1, kSide);
    t.max_levels_16 = j.value("max_levels_16", t.max_levels_16);
    if (t.max_levels_16 < 0 || t.max_levels_16 > 16)
      throw InputError(file.string() + ": /max_levels_16: must be 0..16 (POV's float32 colours give 2)");
    const auto pixels = j.value("pixels", nlohmann::json::array());
    std::map<std::pair<int, int>, std::size_t> first_at;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const auto& p = pixels[i];
      const std::string at = file.string() + ": /pixels/" + std::to_string(i);
      if (!p.is_object()) throw InputError(at + ": expected an object {\"x\", \"y\", \"levels\", \"cause\"}");
      for (const char* k : {"x", "y", "levels"})
        if (p.contains(k) && !p.at(k).is_number_integer()) throw InputError(at + "/" + k + ": expected an integer");
      if (p.contains("cause") && !p.at("cause").is_string()) throw InputError(at + "/cause: expected a string");
      for (auto it = p.begin(); it != p.end(); ++it)
        if (it.key() != "x" && it.key() != "y" && it.key() != "levels" && it.key() != "cause")
          throw InputError(at + "/" + it.key() + ": unknown key");
      for (const char* k : {"x", "y", "cause"})
        if (!p.contains(k)) throw InputError(at + ": needs \"" + k + "\"");
      if (!p.contains("levels"))
        throw InputError(at + ": needs \"levels\", the largest difference allowed there (8-bit levels)");
      side(p.at("x"), at + "/x", 0, t.width.value_or(kSide) - 1);
      side(p.at("y"), at + "/y", 0, t.height.value_or(kSide) - 1);
      if (const long long l = p.at("levels").get<long long>(); l < 1 || l > 255)
        throw InputError(at + "/levels: must be 1..255");
      ExplainedPixel e{p.at("x").get<int>(), p.at("y").get<int>(), p.at("levels").get<int>(),
                       p.at("cause").get<std::string>()};
      if (e.levels < 1 || e.levels > 255) throw InputError(at + "/levels: must be 1..255");
      if (e.cause.empty()) throw InputError(at + ": every listed pixel needs its cause");
      // A pixel listed twice was accepted, the later entry silently winning.
      if (const auto [it, fresh] = first_at.try_emplace({e.x, e.y}, i); !fresh)
        throw InputError(located(at, 0,
                                 "pixel (" + std::to_string(e.x) + ", " + std::to_string(e.y) +
                                     ") listed twice (first at /pixels/" + std::to_string(it->second) + ")"));
      t.pixels.push_back(e);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": " + json_error_text(e));
  }
  return t;
}

PovVerdict judge(const ImageComparison& c, const PovTolerance& t) {
  PovVerdict v;
  const std::string where = t.file.empty() ? "(no tolerance file: identical at 8 bits required)" : t.file.string();
  const bool list_applies = (!t.width || *t.width == c.width) && (!t.height || *t.height == c.height);
  std::map<std::pair<int, int>, const ExplainedPixel*> listed;
  if (list_applies)
    for (const auto& p : t.pixels) listed[{p.x, p.y}] = &p;
  else if (!t.pixels.empty())
    v.lines.push_back("note: the explained pixels in " + where + " are for " + std::to_string(t.width.value_or(0)) +
                      "x" + std::to_string(t.height.value_or(0)) + ", not this size: none apply");
  std::map<std::pair<int, int>, int> seen;
  for (const auto& d : c.differences) {
    seen[{d.x, d.y}] = d.levels;
    const std::string at = "pixel (" + std::to_string(d.x) + ", " + std::to_string(d.y) + ") differs by " +
                           std::to_string(d.levels) + (d.levels == 1 ? " level" : " levels");
    if (auto it = listed.find({d.x, d.y}); it != listed.end()) {
      const int allowed = c.bits == 16 ? allowed_levels_16(it->second->levels) : it->second->levels;
      if (d.levels <= allowed) {
        v.lines.push_back(at + ": explained: " + it->second->cause);
      } else {
        v.pass = false;
        v.lines.push_back(at + ": more than the " + std::to_string(allowed) + " explained in " + where + " (" +
                          it->second->cause + ")");
      }
    } else if (c.bits == 16 && d.levels <= t.max_levels_16) {
      continue;  // POV's float32 colours; counted in the summary, not listed
    } else {
      v.pass = false;
      v.lines.push_back(at + ": NOT explained in " + where);
    }
  }
  for (const auto& [xy, p] : listed)
    if (!seen.count(xy))
      v.lines.push_back("pixel (" + std::to_string(xy.first) + ", " + std::to_string(xy.second) + ") is listed in " +
                        where + " but no longer differs: remove it");
  return v;
}

}  // namespace ra
