// `rayaudit crack-maps -o DIR`: closed meshes rendered far from the origin
// with each triangle method in float, leaks painted red (validation/images/crack_maps.h).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/file_identity.h"
#include "command.h"
#include "images/crack_maps.h"
#include "errors.h"
#include "scene/scene_mesh.h"

namespace {

using ra::cli::split_list;

struct Args {
  std::string out;
  std::vector<std::string> meshes;
  std::string offsets = "1,1e3,1e5,1e7", methods;
  int size = 96, threads = 0;
};

std::vector<double> parse_offsets(const std::string& list) {
  std::vector<double> out;
  for (const auto& s : split_list(list, "--offsets")) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || !std::isfinite(v) || v < 0 || v > 1e30)
      throw ra::InputError("--offsets: '" + s + "' is not an offset between 0 and 1e30");
    out.push_back(v);
  }
  if (out.empty()) throw ra::InputError("--offsets: give at least one offset");
  // Each offset is a map per mesh and method: 50k offsets ran for minutes.
  constexpr std::size_t kMaxOffsets = 100;
  if (out.size() > kMaxOffsets)
    throw ra::InputError("--offsets: " + std::to_string(out.size()) + " offsets, more than the limit of " +
                         std::to_string(kMaxOffsets));
  return out;
}

// "1", "1e3", "1e7", "2.5e4": short, and safe in a file name.
std::string offset_label(double v) {
  const double e = std::round(std::log10(v));
  if (v > 0 && e >= 3 && v == std::pow(10.0, e)) return "1e" + std::to_string(int(e));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  std::string s = buf;
  for (char& c : s)
    if (c == '+') c = 'p';
  return s;
}

// At most 2^24 pixels over all maps (about 20 core-minutes; the default
// run is 590k).
constexpr double kMaxPixelMaps = 16777216;

// The ladder's closed mesh the maps use unless --mesh is given.
std::filesystem::path default_ladder_mesh() { return ra::cache_dir() / "corpus" / "ladder" / "elephant_cgal.obj"; }

// Progress: redrawn in place on a terminal; otherwise (CI logs) a line
// every 10 s with an estimate of the rest, as audit prints (it was
// silent for hours), so a long run shows it is alive and how long it has.
std::function<void(std::size_t, std::size_t)> progress_count() {
  using clock = std::chrono::steady_clock;
  if (isatty(STDERR_FILENO))
    return [](std::size_t done, std::size_t total) {
      std::fprintf(stderr, "\rcrack maps: %zu/%zu mesh x offset", done, total);
      if (done == total) std::fprintf(stderr, "\r%40s\r", "");
      std::fflush(stderr);
    };
  const auto start = clock::now();
  return [start, last = start](std::size_t done, std::size_t total) mutable {
    const auto now = clock::now();
    if (done >= total || std::chrono::duration<double>(now - last).count() < 10) return;
    last = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    std::fprintf(stderr, "crack maps: %zu/%zu mesh x offset, about %.0f s left\n", done, total,
                 elapsed / double(done) * double(total - done));
    std::fflush(stderr);
  };
}

void run(const Args& a) {
  if (a.size < 8 || a.size > 1024) throw ra::InputError("--size must be 8 to 1024 pixels");
  ra::crack::Options opt;
  opt.size = a.size;
  opt.threads = a.threads;
  opt.offsets = parse_offsets(a.offsets);
  opt.methods = split_list(a.methods, "--methods");
  opt.progress = progress_count();
  const std::filesystem::path dir(a.out);
  if (std::filesystem::exists(dir) && !std::filesystem::is_directory(dir))
    throw ra::InputError(a.out + ": exists and is not a directory");
  const std::filesystem::path parent = std::filesystem::absolute(dir).parent_path();
  if (!std::filesystem::is_directory(parent)) throw ra::InputError(a.out + ": its parent directory does not exist");

  // Absurd work is refused up front with its size, before any mesh is read
  // (the flags' own limits allowed ~34 hours, silently). A
  // pixel of a map costs tens of microseconds (a closed mesh far from the
  // origin, and the oracle).
  {
    const std::uint64_t n_meshes = 1 + (a.meshes.empty() ? 1 : a.meshes.size());
    const std::uint64_t maps = n_meshes * ra::crack::map_methods(opt).size() * opt.offsets.size();
    const double pixel_maps = double(maps) * double(opt.size) * double(opt.size);
    if (pixel_maps > kMaxPixelMaps)
      throw ra::InputError("crack-maps: " + std::to_string(maps) + " maps of " + std::to_string(opt.size) + "x" +
                           std::to_string(opt.size) + " pixels are " + std::to_string((long long)pixel_maps) +
                           " pixels (about " + std::to_string((long long)(pixel_maps * 75e-6 / 60)) +
                           " core-minutes); the limit is " + std::to_string((long long)kMaxPixelMaps) +
                           ": fewer --offsets or --methods, or a smaller --size");
  }
  std::vector<ra::crack::ClosedMesh> meshes{ra::crack::audit_sphere()};
  if (a.meshes.empty()) {
    const auto f = default_ladder_mesh();
    if (!std::filesystem::exists(f))
      throw ra::InputError(f.string() + ": missing (ci/fetch-corpus.sh fetches the mesh ladder)");
    meshes.push_back(ra::crack::closed_obj(f));
    ra::note_input(f);
  }
  // Each --mesh is an input: a map named like it is refused, not written
  // over it.
  for (const auto& m : a.meshes) {
    meshes.push_back(ra::crack::closed_obj(m));
    ra::note_input(m);
  }

  // Every output named and checked before the work (a name too
  // long failed after it, leaving one map; a --mesh named sphere.obj shared
  // the built-in sphere's names and one of each pair was lost).
  std::vector<std::filesystem::path> outputs{dir / "crack_maps.json"};
  const auto methods = ra::crack::map_methods(opt);  // throws on an unknown method
  for (const auto& mesh : meshes)
    for (const double offset : opt.offsets)
      for (const auto& method : methods)
        outputs.push_back(dir / (mesh.name + "-" + method + "-" + offset_label(offset) + ".png"));
  for (std::size_t i = 1; i < outputs.size(); ++i)
    for (std::size_t k = 0; k < i; ++k)
      if (outputs[k] == outputs[i])
        throw ra::InputError(outputs[i].string() +
                             ": two maps would have this name (meshes of one name, or "
                             "offsets or methods given twice): rename the mesh or drop the repeat");
  for (const auto& o : outputs) ra::check_output_name(o);
  // The directory is made now and removed again if the run fails in it.
  std::error_code ec;
  const bool made_dir = !std::filesystem::exists(dir, ec);
  std::filesystem::create_directories(dir, ec);
  if (ec) throw ra::InputError(ra::located(a.out, 0, "cannot create the directory: " + ec.message()));
  struct RemoveIfFailed {
    std::filesystem::path dir;
    bool armed;
    ~RemoveIfFailed() {
      std::error_code e;
      if (armed) std::filesystem::remove(dir, e);  // only if empty: nothing of ours is left in it
    }
  } cleanup{dir, made_dir};
  ra::OutputBatch batch(outputs);
  const auto maps = ra::crack::render_maps(meshes, opt);
  nlohmann::json j = {{"size", opt.size},
                      {"precision", "float"},
                      {"offsets", opt.offsets},
                      {"legend",
                       "grey: hit (shaded by angle); red: leak (the oracle finds a crossing, "
                       "this method none); blue: hit where the oracle finds no crossing; white: background"}};
  nlohmann::json ms = nlohmann::json::array(), entries = nlohmann::json::array();
  for (const auto& m : meshes) ms.push_back({{"name", m.name}, {"source", m.source}, {"triangles", m.faces.size()}});
  j["meshes"] = ms;
  std::printf("%-14s %-16s %10s %8s %8s %8s\n", "MESH", "METHOD", "OFFSET", "SURFACE", "LEAKS", "F.HITS");
  if (maps.size() + 1 != outputs.size()) throw std::logic_error("crack-maps: maps and their names disagree");
  for (std::size_t i = 0; i < maps.size(); ++i) {
    const auto& m = maps[i];
    ra::write_image(outputs[i + 1], m.image);
    entries.push_back({{"mesh", m.mesh},
                       {"method", m.method},
                       {"precision", "float"},
                       {"offset", m.offset},
                       {"pixels", m.pixels},
                       {"surface_pixels", m.surface},
                       {"leaks", m.leaks},
                       {"false_hits", m.false_hits},
                       {"image", outputs[i + 1].filename().string()}});
    std::printf("%-14s %-16s %10g %8lld %8lld %8lld\n", m.mesh.c_str(), m.method.c_str(), m.offset, m.surface, m.leaks,
                m.false_hits);
  }
  j["maps"] = entries;
  ra::write_text_atomically(outputs[0], j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  batch.commit();
  cleanup.armed = false;
  std::cout << "wrote " << maps.size() << " maps and crack_maps.json into " << a.out << "\n";
}

void setup(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "crack-maps", "Render closed meshes far from the origin with each triangle method in float; paint leaks red");
  cmd->add_option("-o,--out", a->out, "Directory for crack_maps.json and one PNG per mesh x method x offset")
      ->required();
  cmd->add_option(
      "--mesh", a->meshes,
      "A closed OBJ to map besides the audit's sphere (default: the ladder's elephant_cgal.obj, 5,558 triangles)");
  cmd->add_option("--offsets", a->offsets, "Comma-separated offsets of the mesh centre (o, o, o)")
      ->capture_default_str()
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--methods", a->methods, "Comma-separated triangle methods (default: all)")
      ->check(ra::cli::non_empty_list());
  cmd->add_option("--size", a->size, "Pixels a side")->capture_default_str();
  cmd->add_option("--threads", a->threads, "Threads (0: all cores)")->check(CLI::Range(0, 1024));
  cmd->callback([a] { run(*a); });
}

ra::cli::Registrar reg(35, setup);

}  // namespace
