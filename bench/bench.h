// rayaudit-bench: one Google Benchmark program for the methods,
// the documents' optimisations and the peers. Shared pieces of its groups.
#pragma once
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "render.h"
#include "scene/scene.h"

namespace rb {

namespace fs = std::filesystem;

// What the command line chose (main.cpp fills it before registering).
struct Config {
  bool quick = false;
  int threads_all = 2;  // the "all threads" rows: --threads N, else every core
};
Config& config();
// {1, all} without repeats.
std::vector<int> thread_counts();
// Google Benchmark's --benchmark_repetitions and --benchmark_min_time for
// every row (set globally: per-row settings would append "/min_time:...",
// "/repeats:..." to the names users' scripts read). So every row's iteration is
// one fixed piece of work (one pass over its rays or its batch), and GB's
// time per iteration compares across runs (compare.py).
int repetitions();
double min_time();
double thread_cpu_seconds();

// Registers a benchmark named `name` that needs the corpus files `needs`
// (checked before anything runs), and records it for --filter's check.
struct Registered {
  std::string name;
  std::vector<fs::path> needs;
};
std::vector<Registered>& registered();
benchmark::internal::Benchmark* add(const std::string& name, std::vector<fs::path> needs,
                                    std::function<void(benchmark::State&)> fn);

// Lines printed after the table (hit-count agreement with the peers...).
void note(const std::string& line);
const std::vector<std::string>& notes();

double seconds_since(std::chrono::steady_clock::time_point t0);
inline std::chrono::steady_clock::time_point now() { return std::chrono::steady_clock::now(); }

// Calls f(begin, end) over blocks of [0, n) on `threads` threads (the
// caller is one of them); blocks of 1024 are handed out in turn, so that
// cheap and costly rays mix.
void parallel_for(int threads, std::size_t n, const std::function<void(std::size_t, std::size_t)>& f);

// Heap bytes allocated through operator new and not yet freed, and the peak
// since the last reset (main.cpp replaces the global operator new).
long heap_live();
long heap_peak();
void heap_reset_peak();

// ---- The mesh ladder (../shared/CORPUS.md, scenes/corpus/) ----
struct Rung {
  std::string name;       // in benchmark names: box, teapot, ...
  std::string scene;      // scenes/corpus/NAME.json
  std::string obj;        // corpus/ladder/FILE.obj
  std::size_t triangles;  // checked when loaded
  bool closed;            // culling applies (cull_unsafe_reason is empty)
  bool quick;             // part of --quick
};
const std::vector<Rung>& ladder();
const Rung* find_rung(const std::string& name);
fs::path rung_obj(const Rung& r);
fs::path rung_scene_file(const Rung& r);

// The rays every tracer of a rung traces, ours and the peers alike:
// primary rays through the pixel centres of a 1280 x 960 image framing the
// mesh (the camera framing of scene.h's apply_content_defaults), and shadow
// rays from the hits of those (hit point -> a light above and right of the
// camera; only where the light is on the seen side of the surface).
inline constexpr int kWidth = 1280, kHeight = 960;
struct RungRays {
  std::unique_ptr<ra::Scene> scene;  // at 1280 x 960, the camera framing the mesh
  const ra::TriangleSet* mesh = nullptr;
  std::vector<ra::Rayd> primary, shadow;
  ra::Vec3d light;
};
// Loaded on first use; one rung is kept at a time (the dragon's rays and
// tracers take hundreds of MB).
RungRays& rung_rays(const Rung& r);

// Our tracer on a rung with an acceleration and culling, built once (per
// rung kept); build_s and bytes_per_triangle (heap growth of the build).
struct BuiltTracer {
  std::unique_ptr<ra::Tracer> tracer;
  double build_s = 0;
  double bytes_per_triangle = 0;
};
// `method`: the registry's triangle method (moller, the default, has the
// BVH's 4-lane leaves).
BuiltTracer& our_tracer(const Rung& r, ra::Accel accel, bool cull, const std::string& method = "moller");

// At most `max_rays` of the rays, evenly spread over the set (all if fewer).
std::vector<ra::Rayd> subset(const std::vector<ra::Rayd>& rays, std::size_t max_rays);

// Our closest hits (primary) or any hits (shadow) over `rays` on `threads`
// threads; returns the number of rays that hit.
std::size_t trace_ours(const ra::Tracer& t, const std::vector<ra::Rayd>& rays, bool shadow, int threads,
                       std::vector<unsigned char>* hit_flags = nullptr);

// ---- The groups; each registers its benchmarks ----
void register_kernel();
void register_scene();
void register_embree();
void register_pov();
void register_cgal();
void register_obj();
void register_oracle();

}  // namespace rb
