// Groups obj/FILE/serial|parallel (our OBJ parser, renderer/formats/mesh.h) and
// peer/tinyobjloader/FILE (tinyobjloader on the same file, each iteration
// timing ours right before it): parse rate and peak heap bytes per triangle.
// Ours maps the file read-only instead of copying it to the heap; tinyobj
// streams it: neither holds the file on the heap. "parallel" is the default
// a user gets (threads = 0): files under ObjOptions::parallel_min_bytes
// (8 MB; the bunny is 2.4 MB) parse serially anyway.
#include <tiny_obj_loader.h>

#include "bench.h"
#include "formats/mesh.h"
#include "scene/scene_mesh.h"

namespace rb {
namespace {

fs::path ladder_file(const std::string& file) { return ra::cache_dir() / "corpus" / "ladder" / file; }

struct Parsed {
  double seconds = 0;
  std::size_t triangles = 0;
  long peak_bytes = 0;
};

// The result is destroyed outside the timed part, for both parsers alike.
template <class Parse>
Parsed measure(Parse&& parse) {
  heap_reset_peak();
  const long base = heap_live();
  const auto t0 = now();
  auto result = parse();
  Parsed p;
  p.seconds = seconds_since(t0);
  p.peak_bytes = heap_peak() - base;
  p.triangles = result.second;
  benchmark::DoNotOptimize(result.first);
  return p;
}

Parsed parse_ours(const fs::path& file, int threads) {
  return measure([&] {
    ra::ObjOptions opt;
    opt.threads = threads;
    auto m = std::make_unique<ra::Mesh>(ra::load_obj(file, opt));
    const std::size_t n = m->triangles.size();
    return std::make_pair(std::move(m), n);
  });
}

struct Tiny {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
};

Parsed parse_tiny(const fs::path& file) {
  return measure([&] {
    auto r = std::make_unique<Tiny>();
    std::string warn, err;
    if (!tinyobj::LoadObj(&r->attrib, &r->shapes, &r->materials, &warn, &err, file.c_str(), file.parent_path().c_str(),
                          true))
      throw std::runtime_error("tinyobjloader: " + err);
    std::size_t n = 0;
    for (auto& s : r->shapes) n += s.mesh.num_face_vertices.size();
    return std::make_pair(std::move(r), n);
  });
}

void bm_ours(benchmark::State& state, const fs::path& file, int threads) {
  Parsed last;
  double secs = 0;
  long peak = 0;
  for (auto _ : state) {
    last = parse_ours(file, threads);
    secs += last.seconds;
    peak = std::max(peak, last.peak_bytes);
  }
  state.SetBytesProcessed(long(state.iterations()) * long(fs::file_size(file)));
  state.counters["triangles"] = double(last.triangles);
  state.counters["peak_bytes_per_tri"] = double(peak) / double(last.triangles);
  state.counters["MB_per_s"] = double(fs::file_size(file)) * double(state.iterations()) / secs / 1e6;
}

// tinyobjloader with ours (the default a user gets, threads = 0) right
// before it on the same file; ratio = our parse rate / tinyobj's.
void bm_tiny(benchmark::State& state, const fs::path& file) {
  Parsed last, ours;
  double secs = 0, ours_secs = 0;
  long peak = 0, ours_peak = 0;
  for (auto _ : state) {
    ours = parse_ours(file, 0);
    ours_secs += ours.seconds;
    ours_peak = std::max(ours_peak, ours.peak_bytes);
    last = parse_tiny(file);
    secs += last.seconds;
    peak = std::max(peak, last.peak_bytes);
  }
  if (last.triangles != ours.triangles)
    return state.SkipWithError(
        ("tinyobjloader read " + std::to_string(last.triangles) + " triangles, ours " + std::to_string(ours.triangles))
            .c_str());
  state.SetBytesProcessed(long(state.iterations()) * long(fs::file_size(file)));
  state.counters["triangles"] = double(last.triangles);
  state.counters["peak_bytes_per_tri"] = double(peak) / double(last.triangles);
  state.counters["ours_peak_bytes_per_tri"] = double(ours_peak) / double(last.triangles);
  state.counters["MB_per_s"] = double(fs::file_size(file)) * double(state.iterations()) / secs / 1e6;
  state.counters["ours_MB_per_s"] = double(fs::file_size(file)) * double(state.iterations()) / ours_secs / 1e6;
  state.counters["ratio"] = secs / ours_secs;
}

}  // namespace

void register_obj() {
  for (const char* name : {"bunny", "dragon"}) {
    const Rung* r = find_rung(name);
    if (config().quick && !r->quick) continue;
    const fs::path file = ladder_file(r->obj);
    const std::string stem = fs::path(r->obj).stem().string();
    for (int threads : {1, 0})
      add("obj/" + stem + (threads == 1 ? "/serial" : "/parallel"), {file}, [=](benchmark::State& s) {
        bm_ours(s, file, threads);
      })->Unit(benchmark::kMillisecond);
    add("peer/tinyobjloader/" + stem, {file}, [=](benchmark::State& s) {
      bm_tiny(s, file);
    })->Unit(benchmark::kMillisecond);
  }
}

}  // namespace rb
