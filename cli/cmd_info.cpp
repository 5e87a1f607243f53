// `rayaudit info FILE [--json] [--threads N]`: what an OBJ file holds, as the
// loader sees it (counts after triangulation, area, bbox, names, warnings).
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "command.h"
#include "errors.h"
#include "formats/mesh.h"

namespace {

struct Opts {
  std::string file;
  bool json = false;
  int threads = 1;
};

void setup(CLI::App& app) {
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("info", "Summarise an OBJ file (counts, area, bounding box, materials)");
  cmd->add_option("FILE", o->file, "OBJ file")->required();
  cmd->add_flag("--json", o->json, "Print one JSON object on stdout");
  cmd->add_option("--threads", o->threads, "Parser threads (0 = all cores)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  cmd->callback([o] {
    ra::ObjOptions opt;
    opt.threads = o->threads;
    // A PLY, OFF or scene JSON read as an OBJ of unknown statements: an
    // empty mesh and exit 0; render refuses them by name.
    std::string ext = std::filesystem::path(o->file).extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".ply" || ext == ".off" || ext == ".json")
      throw ra::InputError(ra::located(o->file, 0,
                                       "a " + ext.substr(1) + " file: info reads OBJ meshes" +
                                           (ext == ".json" ? std::string() : " (rayaudit convert it to OBJ first)")));
    const ra::Mesh m = ra::load_obj(o->file, opt);
    const ra::Bounds3d b = m.bbox();
    auto vec = [](const ra::Vec3d& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
    if (o->json) {
      nlohmann::json j;
      j["file"] = m.path;
      j["vertices"] = m.positions.size();
      j["normals"] = m.normals.size();
      j["uvs"] = m.uvs.size();
      j["triangles"] = m.triangles.size();
      j["area"] = m.area();
      j["bbox"] = b.empty() ? nlohmann::json(nullptr) : nlohmann::json{{"min", vec(b.min)}, {"max", vec(b.max)}};
      j["groups"] = m.groups;
      j["objects"] = m.objects;
      nlohmann::json mats = nlohmann::json::array();
      for (auto& mt : m.materials) mats.push_back(mt.name);
      j["materials"] = mats;
      j["skipped"] = {{"vp", m.skipped.vp}, {"l", m.skipped.l}, {"p", m.skipped.p}};
      j["warnings"] = m.warnings;
      // Names are bytes from the file: invalid UTF-8 becomes U+FFFD.
      std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
      return;
    }
    for (auto& w : m.warnings) std::cerr << "warning: " << w << "\n";
    std::printf("%s\n", m.path.c_str());
    std::printf("  vertices   %zu\n  normals    %zu\n  uvs        %zu\n  triangles  %zu\n", m.positions.size(),
                m.normals.size(), m.uvs.size(), m.triangles.size());
    std::printf("  area       %.17g\n", m.area());
    if (!b.empty())
      std::printf("  bbox       (%.9g, %.9g, %.9g) .. (%.9g, %.9g, %.9g)\n", b.min.x, b.min.y, b.min.z, b.max.x,
                  b.max.y, b.max.z);
    std::printf("  groups     %zu\n  objects    %zu\n  materials  %zu", m.groups.size(), m.objects.size(),
                m.materials.size());
    for (size_t i = 0; i < m.materials.size() && i < 8; ++i)
      std::printf("%s%s", i ? ", " : " (", m.materials[i].name.c_str());
    std::printf("%s\n", m.materials.empty() ? "" : (m.materials.size() > 8 ? ", ...)" : ")"));
    std::printf("  skipped    vp %ld, l %ld, p %ld\n  warnings   %zu\n", m.skipped.vp, m.skipped.l, m.skipped.p,
                m.warnings.size());
  });
}

ra::cli::Registrar reg(30, setup);

}  // namespace
