// Case families for the audit: seeded, reproducible generators of rays and
// triangles (or spheres), each with a sweep parameter (REFERENCES.md).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <rayaudit/ray.h>
#include <rayaudit/registry.h>

namespace ra::audit {

enum class Precision { f32, f64 };
const char* precision_name(Precision p);  // "float" / "double"

struct Tri {
  Vec3d a, b, c;
};

// One ray tested against triangles [first, first + count) of its batch. A
// probe with count > 1 is a group (edge pair, vertex fan, closed mesh):
// leaks and double hits are judged over the group.
struct Probe {
  Rayd ray;
  int first = 0;
  int count = 1;
  // A closed mesh around the origin: every ray must leave through it, so it
  // is judged for leaks without the group_is_proper test.
  bool closed = false;
  // Refracted family: the triangle of the group the primary ray enters
  // through (the group is a closed convex mesh; -1 elsewhere).
  int entry = -1;
};

struct TriangleBatch {
  std::vector<Tri> tris;
  std::vector<Probe> probes;
};

struct SphereCase {
  Rayd ray;
  Vec3d center;
  double radius = 1;
};

struct Family {
  std::string name;
  Kind kind;                       // triangle or sphere
  std::string param;               // what the sweep varies, e.g. "offset"
  std::vector<std::string> sweep;  // one label per sweep value
  bool grouped = false;            // probes hold several triangles
  bool secondary = false;          // spawned rays (handled by the audit engine)
  bool refracted = false;          // spawned rays enter the solid (secondary is set too)
  // Triangles each probe tests, for turning a case budget into probes.
  int tris_per_probe(int sweep_index) const;
  // Tests each probe counts for --rays: the 2 spawned rays of a secondary
  // probe (reflection and shadow), otherwise its primitives (a refracted
  // probe's one spawned ray is tested against every triangle of its mesh,
  // 46 on average, though it books one test: its nearest hit).
  int tests_per_probe(int sweep_index) const;
};

// All families, triangles first, in a fixed order. A name may stand for a
// triangle and a sphere family both (`refracted`): --families NAME grades
// every method with it.
const std::vector<Family>& families();
const Family* find_family(const std::string& name);  // the first of that name
const Family* find_family(const std::string& name, Kind kind);
std::vector<const Family*> families_named(const std::string& name);
std::string family_names();  // each name once

// A deterministic stream per (seed, family, sweep value, chunk): the same
// cases whatever the thread count, shard or which other families run. The
// chunk index is 64-bit (1e10 rays are ~4e7 chunks per sweep value); for
// indices below 2^31 the streams are those of the former int version.
std::uint64_t stream_seed(std::uint64_t seed, const std::string& family, int sweep, std::uint64_t chunk);

// `count` probes of a triangle family. Cases are made in double; for f32 every
// coordinate is then rounded to float, so the oracle judges what the float
// method gets. near-miss steps in ulps of the requested precision.
void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count, TriangleBatch& out);
void generate(const Family& f, int sweep, Precision p, std::uint64_t stream, int count, std::vector<SphereCase>& out);

// A group judged for leaks: every triangle clearly faces the ray's direction
// the same way (no fold seen along d, none edge-on or degenerate).
bool group_is_proper(const Tri* tris, int count, const Vec3d& d);

// The closed-mesh family's meshes as triangles around the origin, before any
// placement or grid snapping: shape 0 is the tessellated sphere (80
// triangles, radius 2), 1 the cube [-1, 1]^3 (12). Outward winding.
std::vector<Tri> closed_mesh_triangles(int shape);

// The secondary family's sweep index = strategy * scales + scale index;
// the refracted families share the sweep.
int secondary_strategy(int sweep);

// Refracted rays enter glass of this index of refraction from air.
inline constexpr double kRefractedIor = 1.5;

}  // namespace ra::audit
