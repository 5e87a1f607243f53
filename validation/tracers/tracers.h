// Whole tracers graded, not just their triangle tests: a BVH (or any other
// search) can lose a hit that every leaf test would find. Closed meshes
// (the audit's tessellated sphere and its cube) are placed from the origin
// out to 1e7 and scaled 1e-4..1e4, in float (every tracer sees the same
// float vertices, as Embree stores them), and rays are cast
//  - from points inside (each must hit: Embree's verify test, which fails
//    above a miss rate of 2e-5), a third aimed exactly at a vertex, a third
//    at an edge, a third in a random direction;
//  - from outside through a vertex or an edge point into the solid (they
//    must hit where the exact ray enters the solid: two crossings more
//    than 2^-10 of the mesh's size apart; a ray that only grazes the
//    silhouette, or misses it by less than 2^-10 of the size, is not
//    judged: a hit and a miss are both right within rounding there).
// A miss where the exact ray (ra::oracle over every triangle) crosses the
// mesh is a leak; a hit where it does not is a false hit; a hit whose t is
// not the exact nearest crossing's within the tracer's bound (64 roundings
// of its precision, of |o| + |t d| on the ray's largest axis) is a wrong
// nearest. Figures per million rays per placement and scale.
//
// A user's own tracer (link rayaudit::validation):
//   auto mine = ra::tracers::tracer_subject<MyBvh>("mine", Precision::f32,
//       [](const ra::tracers::Mesh& m) { return MyBvh(m.positions, m.triangles); },
//       [](const MyBvh& b, const ra::Rayd& r) -> std::optional<ra::tracers::Hit> { ... });
//   EXPECT_TRUE(ra::tracers::IsLeakFree(mine));   (tracers_gtest.h)
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "exact/families.h"

namespace ra::tracers {

using audit::Precision;

struct Mesh {
  std::vector<Vec3d> positions;  // float values (exact in float)
  std::vector<std::array<int, 3>> triangles;
};
struct Hit {
  double t = 0;
  int prim = -1;
};
using IntersectFn = std::function<std::optional<Hit>(const Rayd&)>;
// Builds the tracer over a mesh; the callable it returns answers rays
// (closest hit in the ray's window) until the next build.
using BuildFn = std::function<IntersectFn(const Mesh&)>;

struct Subject {
  std::string name;                      // e.g. "bvh/moller/float", "embree", "mine"
  Precision precision = Precision::f64;  // for the wrong-nearest bound
  BuildFn build;
};

// A user's tracer from a build callable (Mesh -> S) and an intersect
// callable (const S&, ray -> optional<Hit>).
template <class S, class Build, class Intersect>
Subject tracer_subject(std::string name, Precision p, Build build, Intersect intersect) {
  return {std::move(name), p, [build, intersect](const Mesh& m) -> IntersectFn {
            auto s = std::make_shared<S>(build(m));
            return [s, intersect](const Rayd& r) { return intersect(*s, r); };
          }};
}

// The tracer names `rayaudit audit --tracers` knows: bvh, sphere, none (ours,
// every triangle method and precision, or NAME:METHOD[/PRECISION]), embree,
// embree-robust, cgal-aabb. Throws std::invalid_argument listing them for
// an unknown name.
std::vector<Subject> named(const std::string& name);
std::string known_names();

struct Stats {
  std::uint64_t rays = 0, inside_rays = 0, leaks = 0, inside_leaks = 0, false_hits = 0, wrong_nearest = 0;
  void merge(const Stats& o);
  double per_million(std::uint64_t n) const { return rays ? 1e6 * double(n) / double(rays) : 0; }
  nlohmann::json to_json() const;
};
struct Cell {
  std::size_t subject;
  std::string shape;  // sphere, cube
  double offset = 0, scale = 1;
  Stats stats;
};
struct Options {
  long long rays = 2000;  // per shape, offset and scale (half from inside)
  std::uint64_t seed = 1;
};
struct Report {
  std::vector<std::string> subjects;
  std::vector<double> offsets, scales;
  std::vector<Cell> cells;
  // Placements float cannot hold (its spacing there above 1/64 of the
  // mesh's size): not judged, listed.
  std::vector<std::pair<double, double>> skipped;
  Stats total(std::size_t subject) const;
  nlohmann::json to_json() const;
  std::string summary_table() const;
};

// Embree's verify test's bar: a tracer fails it above this miss rate.
inline constexpr double kEmbreeMissRate = 2e-5;

Report run(const std::vector<Subject>& subjects, const Options& opt);

}  // namespace ra::tracers
