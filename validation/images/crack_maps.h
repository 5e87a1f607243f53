// Crack maps: a closed mesh rendered far from the origin with each
// triangle method in float, every pixel whose ray passes through the surface
// (the oracle or the watertight method finds a crossing, the method none) red.
#pragma once
#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <rayaudit/image.h>
#include <rayaudit/vec.h>

namespace ra::crack {

// A closed mesh centred on the origin with bounding radius 2 (the audit's
// sphere radius), so every offset moves the same shape.
struct ClosedMesh {
  std::string name;    // "sphere", or the OBJ's stem
  std::string source;  // where it comes from, for the report
  std::vector<Vec3d> positions;
  std::vector<std::array<int, 3>> faces;
};

// The audit's closed-mesh family sphere (80 triangles, radius 2).
ClosedMesh audit_sphere();
// An OBJ (through the scene loader), centred and scaled to radius 2. Throws
// InputError when it is not closed: cracks are only defined on a closed surface.
ClosedMesh closed_obj(const std::filesystem::path& file);

struct Options {
  int size = 96;                                  // square maps, pixels a side
  std::vector<double> offsets{1, 1e3, 1e5, 1e7};  // mesh centre at (o, o, o)
  std::vector<std::string> methods;               // empty: every triangle method
  int threads = 0;                                // 0: all cores
  std::function<void(std::size_t done, std::size_t total)> progress;
};

struct Map {
  std::string mesh, method;
  double offset = 0;
  Image image;               // grey: hit; red: leak; blue: hit where exactly nothing is; white: background
  long long pixels = 0;      // size * size
  long long surface = 0;     // pixels whose ray meets the mesh (oracle or watertight)
  long long leaks = 0;       // of those, where this method hits nothing
  long long false_hits = 0;  // hits where the oracle finds no crossing
};

// One map per mesh x offset x method (mesh-major). The oracle judges the
// float-rounded ray against the float-rounded triangles, as the method sees them.
std::vector<Map> render_maps(const std::vector<ClosedMesh>& meshes, const Options& opt);

// The methods render_maps() uses for opt.methods, in its order (InputError
// for an unknown name): lets a command name every output before the work.
std::vector<std::string> map_methods(const Options& opt);

}  // namespace ra::crack
