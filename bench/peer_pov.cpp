// Group peer/pov/MESH/threads=T: POV-Ray 3.7 rendering the scene that
// `rayaudit export-pov` writes (1280 x 960, +WT<T>), against our tracer on
// the same scene in the same iteration. POV's own parse (+ bounding) and
// trace seconds come from its statistics output; the whole process is timed
// too, against `rayaudit render` run as a process the same way.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

#include "io/atomic_file.h"
#include "bench.h"
#include "errors.h"
#include "pov/pov_export.h"
#include "pov/pov_runner.h"

namespace rb {
namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// "  Parse Time:  0 hours  0 minutes  1 seconds (1.234 seconds)" and the
// next line's "using N thread(s) with X CPU-seconds total".
struct PovTime {
  double wall = -1, cpu = -1;
};
PovTime pov_time(const std::string& log, const std::string& what) {
  const std::regex re(what +
                      R"(:[^(\n]*\(([0-9.]+) seconds\)\s*\n\s*using \d+ thread\(s\) with ([0-9.]+) CPU-seconds)");
  std::smatch m;
  PovTime t;
  if (std::regex_search(log, m, re)) {
    t.wall = std::stod(m[1]);
    t.cpu = std::stod(m[2]);
  }
  return t;
}

// A private working directory under /tmp (Debian's povray.conf lets POV
// read and write there), removed at the end.
struct WorkDir {
  fs::path path;
  WorkDir() {
    std::string tmpl = "/tmp/rayaudit-bench-pov-XXXXXX";
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a working directory under /tmp");
    path = tmpl;
  }
  ~WorkDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

fs::path rayaudit_program() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec).parent_path() / "rayaudit";
  if (ec || access(p.c_str(), X_OK) != 0)
    throw std::runtime_error("rayaudit not found beside rayaudit-bench (" + p.string() + ")");
  return p;
}

void bm_pov(benchmark::State& state, const Rung* rung, int threads) {
  RungRays& rr = rung_rays(*rung);
  const fs::path povray = ra::find_povray();
  WorkDir work;
  const ra::PovExport ex = ra::export_pov(*rr.scene);
  ra::write_text_atomically(work.path / "scene.pov", ex.sdl);
  std::string ini = ra::pov_ini(8);
  ini = std::regex_replace(ini, std::regex("Work_Threads=1"), "Work_Threads=" + std::to_string(threads));
  ra::write_text_atomically(work.path / "rayaudit.ini", ini);
  for (const auto& img : ex.images) ra::copy_pov_image(img.source, work.path / img.name);
  const std::vector<std::string> pov_argv = {povray.string(),
                                             "rayaudit.ini",
                                             "+Iscene.pov",
                                             "+Oout.png",
                                             "+W" + std::to_string(kWidth),
                                             "+H" + std::to_string(kHeight),
                                             "+WT" + std::to_string(threads)};
  const std::vector<std::string> ours_argv = {rayaudit_program().string(),
                                              "render",
                                              rung_scene_file(*rung).string(),
                                              "-o",
                                              "ours.png",
                                              "--width",
                                              std::to_string(kWidth),
                                              "--height",
                                              std::to_string(kHeight),
                                              "--threads",
                                              std::to_string(threads)};
  double pov_parse = 0, pov_trace = 0, pov_trace_cpu = 0, pov_proc = 0;
  double ours_parse = 0, ours_trace = 0, ours_proc = 0;
  for (auto _ : state) {
    // Ours in-process: load (OBJ parse, placement) + build, then render.
    auto t0 = now();
    ra::Scene scene = ra::load_scene(rung_scene_file(*rung));
    scene.width = kWidth;
    scene.height = kHeight;
    ra::apply_content_defaults(scene);
    ra::RenderOptions opt;
    opt.progress = false;
    opt.threads = threads;
    ra::Tracer tracer(scene, opt);
    ours_parse += seconds_since(t0);
    t0 = now();
    benchmark::DoNotOptimize(tracer.render());
    ours_trace += seconds_since(t0);
    // Ours as a process, the way a user runs it.
    const ra::ProcessRun op = ra::run_process(work.path, ours_argv, work.path / "ours.out", work.path / "ours.err");
    if (op.code != 0) throw std::runtime_error("rayaudit render failed: " + read_text(work.path / "ours.err"));
    ours_proc += op.wall_s;
    // POV-Ray.
    const ra::ProcessRun pp = ra::run_process(work.path, pov_argv, work.path / "povray.out", work.path / "povray.err");
    const std::string log = read_text(work.path / "povray.err");
    if (pp.code != 0) throw std::runtime_error("POV-Ray failed (exit " + std::to_string(pp.code) + ")");
    const PovTime parse = pov_time(log, "Parse Time"), bound = pov_time(log, "Bounding Time"),
                  trace = pov_time(log, "Trace Time");
    if (parse.wall < 0 || trace.wall < 0) throw std::runtime_error("no Parse/Trace Time in POV-Ray's statistics");
    pov_parse += parse.wall + std::max(0.0, bound.wall);
    pov_trace += trace.wall;
    pov_trace_cpu += trace.cpu;
    pov_proc += pp.wall_s;
  }
  const double n = double(state.iterations());
  state.counters["pov_parse_s"] = pov_parse / n;  // parse + bounding (its BVH)
  state.counters["pov_trace_s"] = pov_trace / n;
  state.counters["pov_trace_cpu_s"] = pov_trace_cpu / n;
  state.counters["pov_process_s"] = pov_proc / n;
  state.counters["ours_parse_s"] = ours_parse / n;  // load_scene + tracer build
  state.counters["ours_trace_s"] = ours_trace / n;  // Tracer::render
  state.counters["ours_process_s"] = ours_proc / n;
  state.counters["triangles"] = double(rung->triangles);
  // Rates are images (or scenes parsed) per second: ours / POV-Ray's.
  state.counters["ratio"] = pov_trace / ours_trace;
  state.counters["parse_ratio"] = pov_parse / ours_parse;
  state.counters["process_ratio"] = pov_proc / ours_proc;
}

}  // namespace

void register_pov() {
  for (const char* name : {"bunny", "dragon"}) {
    const Rung* r = find_rung(name);
    if (config().quick && !r->quick) continue;
    // --quick: one thread only (POV-Ray takes seconds per image).
    for (int t : config().quick ? std::vector<int>{1} : thread_counts())
      add("peer/pov/" + r->name + "/threads=" + std::to_string(t), {rung_obj(*r), rung_scene_file(*r)},
          [=](benchmark::State& s) { bm_pov(s, r, t); })
          ->Unit(benchmark::kMillisecond);
  }
}

}  // namespace rb
